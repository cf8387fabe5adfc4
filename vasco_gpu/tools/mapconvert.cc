// mapconvert: convert a CARMEN map file, or describe it.
//
//   mapconvert [--mode trinary|scale|raw] IN OUT   convert by OUT's extension
//   mapconvert --info IN                           print what the map holds
//
// Exit status: 0 ok, 1 a file could not be read or written (the message
// names it), 2 usage error.
#include <cmath>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <exception>
#include <limits>
#include <string>
#include <vector>

#include "carmen_compat/error.h"
#include "carmen_compat/image_io.h"
#include "carmen_compat/map_file.h"
#include "carmen_compat/map_format.h"
#include "cli_support.h"
#include "vasco_gpu/version.h"

namespace {

const char kUsage[] =
    "Usage: mapconvert [-q] [--mode trinary|scale|raw] IN OUT\n"
    "   or: mapconvert --info IN\n"
    "   or: mapconvert --version\n"
    "\n"
    "Converts the CARMEN map IN (.map or .map.gz) to OUT, chosen by OUT's extension:\n"
    "  .map     CARMEN map (every chunk it reads; HMAP, unknown and repeated chunks\n"
    "           are dropped, with a note)\n"
    "  .map.gz  CARMEN map, gzip-compressed\n"
    "  .pgm     ROS map_server / nav2 image, with a .yaml beside it (origin from the\n"
    "           map's OFFSET chunk, else 0 0 0); --mode sets the YAML mode and the\n"
    "           grey levels (default trinary)\n"
    "  .png     8-bit grey picture (black occupied, white free, mid grey unknown)\n"
    "--info prints the size, resolution, chunks, unknown fraction and value range.\n"
    "-q, --quiet leaves out the notes (chunks not copied); errors are still said.\n"
    "IN '-' reads standard input; OUT '-' writes a CARMEN map (.map) to standard output.\n"
    "\n"
    "Exit status: 0 ok, 1 a file could not be read or written, 2 usage error.\n";

int usage_error(const std::string &msg) {
  std::fprintf(stderr, "mapconvert: %s\n%s", msg.c_str(), kUsage);
  return 2;
}

// A CARMEN map is copied whole (every chunk); any other format of the
// map-format table gets the grid and its origin through the table's writer.
enum class OutKind { None, Map, Pgm, Grid };

// By the map-format table's rule (file_names.h: the extension, any case).
OutKind kind_of(const std::string &path) {
  const carmen::MapFormatEntry *f = carmen::find_map_format(path);
  if (f == nullptr) return OutKind::None;
  if (f->format == carmen::MapFormat::CarmenMap || f->format == carmen::MapFormat::CarmenMapGz) return OutKind::Map;
  return f->format == carmen::MapFormat::PgmYaml ? OutKind::Pgm : OutKind::Grid;
}

std::string quoted(const std::string &s) { return "\"" + s + "\""; }

void print_info(const std::string &path, const carmen::MapFile &m) {
  std::printf("file: %s\n", path.c_str());
  std::printf("comment lines: %zu\n", m.comments.size());
  std::printf("chunks: %zu\n", m.chunks.size());
  for (const carmen::ChunkInfo &c : m.chunks) {
    std::printf("  %-10s %10d bytes at byte %lld%s%s\n", carmen::chunk_type_name(c.type).c_str(), c.size,
                static_cast<long long>(c.offset), c.named() ? (" named " + quoted(c.name)).c_str() : "",
                c.used ? "" : " (skipped)");
  }
  if (m.creator) {
    const carmen::CreatorInfo &c = *m.creator;
    char date[64] = "?";
    const std::time_t t = static_cast<std::time_t>(c.time);
    std::tm tm_utc;
    if (gmtime_r(&t, &tm_utc) != nullptr) std::strftime(date, sizeof date, "%Y-%m-%d %H:%M:%S UTC", &tm_utc);
    std::printf("creator: user %s, time %s (%d-byte time_t%s), origin %s, description %s\n",
                quoted(c.user).c_str(), date, c.time_bytes, m.old_style_creator ? ", old-style chunk" : "",
                quoted(c.origin).c_str(), quoted(c.description).c_str());
  }
  if (m.offset) std::printf("offset: x %g y %g theta %g\n", m.offset->x, m.offset->y, m.offset->theta);
  if (m.places) std::printf("places: %zu\n", m.places->size());
  if (m.offlimits) {
    std::printf("offlimits: %zu points, %zu lines, %zu rectangles\n", m.offlimits->points.size(),
                m.offlimits->lines.size(), m.offlimits->rects.size());
  }
  if (m.laserscans) std::printf("laserscans: %zu\n", m.laserscans->size());
  if (m.unknown_chunks > 0) std::printf("skipped chunks: %d\n", m.unknown_chunks);
  if (!m.gridmap) {
    std::printf("gridmap: none\n");
    return;
  }
  const carmen::GridMap &g = *m.gridmap;
  size_t unknown = 0, offlimits = 0;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (float v : g.cells) {
    if (v == carmen::kUnknownCell) {
      ++unknown;
      continue;
    }
    if (v >= 2.0f) ++offlimits;
    lo = std::min(lo, double(v));
    hi = std::max(hi, double(v));
  }
  const size_t n = g.cells.size();
  std::printf("size: %d x %d cells\n", g.size_x, g.size_y);
  std::printf("resolution: %.9g m\n", g.resolution);
  std::printf("extent: %g x %g m\n", g.size_x * g.resolution, g.size_y * g.resolution);
  std::printf("unknown: %zu of %zu cells (%.2f%%)\n", unknown, n,
              n ? 100.0 * double(unknown) / double(n) : 0.0);
  if (unknown < n) {
    std::printf("known values: min %.9g max %.9g\n", lo, hi);
  } else {
    std::printf("known values: none\n");
  }
  if (offlimits > 0) std::printf("off-limits cells: %zu\n", offlimits);
}

// The command line, parsed.
struct Args {
  bool info = false, mode_given = false, help = false, version = false, quiet = false;
  carmen::PgmMode mode = carmen::PgmMode::Trinary;
  std::vector<std::string> files;
};

// Parses argv into *a; returns 0, or usage_error's code.
int parse_args(const std::vector<std::string> &args, Args *a) {
  for (size_t i = 0; i < args.size(); ++i) {
    const std::string &s = args[i];
    if (s == "--help" || s == "-h") {
      a->help = true;
      return 0;
    } else if (s == "--version") {
      a->version = true;
      return 0;
    } else if (s == "-q" || s == "--quiet") {
      a->quiet = true;
    } else if (s == "--info") {
      a->info = true;
    } else if (s == "--mode" || s.rfind("--mode=", 0) == 0) {
      std::string value;
      if (s == "--mode") {
        if (i + 1 >= args.size()) return usage_error("--mode needs a value");
        value = args[++i];
      } else {
        value = s.substr(7);
      }
      if (!carmen::parse_pgm_mode(value, &a->mode)) {
        return usage_error("unknown --mode '" + value + "' (trinary, scale or raw)");
      }
      a->mode_given = true;
    } else if (s == "--") {
      a->files.insert(a->files.end(), args.begin() + static_cast<long>(i) + 1, args.end());
      break;
    } else if (s.size() > 1 && s[0] == '-') {  // "-" alone is standard input or output
      return usage_error("unknown option '" + s + "'");
    } else {
      a->files.push_back(s);
    }
  }
  return 0;
}

// Checks the files and options go together; sets *kind for a conversion.
// Returns 0, or usage_error's code.
int check_args(const Args &a, OutKind *kind) {
  if (a.info) {
    if (a.files.size() != 1) return usage_error("--info takes one map file");
    if (a.mode_given) return usage_error("--mode applies to .pgm output, not --info");
    return 0;
  }
  if (a.files.size() != 2) return usage_error(a.files.empty() ? "no files given" : "expected IN and OUT");
  *kind = a.files[1] == cli::kStdio ? OutKind::Map : kind_of(a.files[1]);
  if (*kind == OutKind::None) {
    return usage_error("cannot tell the output format of '" + a.files[1] + "' (use .map, .map.gz, .pgm or .png)");
  }
  if (a.mode_given && *kind != OutKind::Pgm) return usage_error("--mode applies to .pgm output only");
  return 0;
}

// Writes map m, read from `in`, to `out` in the format `kind`.
void convert(const std::string &in, const carmen::MapFile &m, const std::string &out, OutKind kind,
             carmen::PgmMode mode, bool quiet) {
  if (kind == OutKind::Map && out == cli::kStdio) {
    const cli::StdoutFile to_stdout(".map");
    carmen::write_map_file(to_stdout.path(), m);
    to_stdout.send();
  } else if (kind == OutKind::Map) {
    carmen::write_map_file(out, m);
  }
  if (kind == OutKind::Map) {
    if (m.unknown_chunks > 0 && !quiet) {
      std::fprintf(stderr, "mapconvert: note: %d chunk(s) of %s not copied (HMAP, unknown or repeated)\n",
                   m.unknown_chunks, in.c_str());
    }
    return;
  }
  if (!m.gridmap) throw carmen::FileError(in, "has no GRIDMAP chunk: there is no image to make");
  carmen::MapToWrite w;
  w.grid = *m.gridmap;
  w.origin = m.offset;
  w.pgm_mode = mode;
  carmen::write_map(out, w);
}

}  // namespace

int main(int argc, char **argv) {
  Args a;
  if (const int rc = parse_args(std::vector<std::string>(argv + 1, argv + argc), &a)) return rc;
  if (a.help) {
    std::fputs(kUsage, stdout);
    return 0;
  }
  if (a.version) {
    std::printf("mapconvert (vasco_gpu) %s\n", vasco::version());
    return 0;
  }
  OutKind kind = OutKind::None;
  if (const int rc = check_args(a, &kind)) return rc;
  try {
    // The output (and a .pgm's .yaml) is checked before the map is read: it
    // must be replaceable and must not be the input.
    if (!a.info && a.files[1] != cli::kStdio) cli::check_outputs({a.files[0]}, carmen::map_output_files(a.files[1]));
    // --info lists named GRIDMAP chunks without parsing them: a file of
    // thousands of them costs their headers, not their cells.
    carmen::MapReadOptions read;
    if (a.info) read.named_chunks = carmen::NamedChunkReading::Index;
    const carmen::MapFile m = carmen::read_map_file(cli::input_path(a.files[0]), read);
    if (a.info) {
      print_info(a.files[0], m);
    } else {
      convert(a.files[0], m, a.files[1], kind, a.mode, a.quiet);
    }
    return 0;
  } catch (const carmen::Error &e) {  // names the file itself
    std::fprintf(stderr, "mapconvert: %s\n", e.what());
    return cli::exit_status(e);
  } catch (const std::exception &e) {
    std::fprintf(stderr, "mapconvert: %s: %s\n", a.files[0].c_str(), e.what());
  }
  return 1;
}
