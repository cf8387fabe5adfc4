// CARMEN's map_io C API on top of carmen_compat/map_file.h: the chunk codes,
// the tests of a file and its chunks, the advance functions on a
// carmen_FILE, and the map server's calls. The writers are in
// map_io_write.cc, the readers in map_io_read.cc, the tools' calls in
// map_io_tools.cc and the HMAP chunk in map_io_hmap.cc.
#include "carmen/map_io.h"

#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

#include "carmen_compat/map_file.h"
#include "carmen_stdio_results.h"
#include "map_io_support.h"

static_assert(CARMEN_MAP_GRIDMAP_CHUNK == carmen::kGridmapChunk, "chunk code");
static_assert(CARMEN_MAP_OFFLIMITS_CHUNK == carmen::kOfflimitsChunk, "chunk code");
static_assert(CARMEN_MAP_HMAP_CHUNK == carmen::kHmapChunk, "chunk code");
static_assert(CARMEN_MAP_PLACES_CHUNK == carmen::kPlacesChunk, "chunk code");
static_assert(CARMEN_MAP_EXPECTED_CHUNK == carmen::kExpectedChunk, "chunk code");
static_assert(CARMEN_MAP_LASERSCANS_CHUNK == carmen::kLaserscansChunk, "chunk code");
static_assert(CARMEN_MAP_CREATOR_CHUNK == carmen::kCreatorChunk, "chunk code");
static_assert(CARMEN_MAP_GLOBAL_OFFSET_CHUNK == carmen::kGlobalOffsetChunk, "chunk code");
static_assert(CARMEN_MAP_NAMED_CHUNK_FLAG == carmen::kNamedChunkFlag, "chunk code");
static_assert(CARMEN_NAMED_POSITION_TYPE == carmen::kNamedPosition, "place type");
static_assert(CARMEN_NAMED_POSE_TYPE == carmen::kNamedPose, "place type");
static_assert(CARMEN_LOCALIZATION_INIT_TYPE == carmen::kLocalizationInit, "place type");

namespace {

using carmen::map_io_detail::guarded;

// carmen_FILE helpers for the advance functions (no exceptions).
bool read_i32(carmen_FILE *fp, int32_t *v) {
  unsigned char b[4];
  if (carmen_fread(b, 1, 4, fp) != 4) return false;
  const uint32_t u = uint32_t(b[0]) | uint32_t(b[1]) << 8 | uint32_t(b[2]) << 16 | uint32_t(b[3]) << 24;
  std::memcpy(v, &u, 4);
  return true;
}

// Rewinds and reads past the comments and the id; false if they are not there.
bool skip_to_first_chunk(carmen_FILE *fp) {
  if (!carmen::checked_seek(fp, 0, SEEK_SET)) return false;
  int c;
  while ((c = carmen_fgetc(fp)) == '#') {
    while ((c = carmen_fgetc(fp)) != EOF && c != '\n') {
    }
    if (c == EOF) return false;
  }
  if (c == EOF) return false;
  const std::string id = std::string(CARMEN_MAP_LABEL) + CARMEN_MAP_VERSION;
  char rest[16];
  if (static_cast<char>(c) != id[0]) return false;
  if (carmen_fread(rest, 1, 16, fp) != 16) return false;
  return std::memcmp(rest, id.data() + 1, 16) == 0;
}

int advance(carmen_FILE *fp, int specific_chunk, const char *chunk_name) {
  if (fp == nullptr || !skip_to_first_chunk(fp)) return -1;
  while (true) {
    const int type = carmen_fgetc(fp);
    if (type == EOF) return -1;
    const long after_type = carmen_ftell(fp);
    const long at_type = after_type - 1;
    int32_t size;
    if (!read_i32(fp, &size) || size < 10) return -1;
    long skip = size;
    if ((type & ~CARMEN_MAP_NAMED_CHUNK_FLAG) == specific_chunk) {
      if (chunk_name == nullptr) return carmen::checked_seek(fp, at_type, SEEK_SET) ? 0 : -1;
      if (type & CARMEN_MAP_NAMED_CHUNK_FLAG) {
        char desc[10];
        if (carmen_fread(desc, 1, 10, fp) != 10) return -1;
        skip -= 10;
        std::string name;
        int c;
        while (skip > 0 && (c = carmen_fgetc(fp)) != EOF) {
          --skip;
          if (c == 0) break;
          name.push_back(static_cast<char>(c));
          if (name.size() > 4096) return -1;
        }
        if (name == chunk_name) return carmen::checked_seek(fp, at_type, SEEK_SET) ? 0 : -1;
      }
    }
    if (!carmen::checked_seek(fp, skip, SEEK_CUR)) return -1;
  }
}

// What carmen_map_set_filename stored (CARMEN's map server would publish it).
std::mutex server_mutex;
std::string server_filename;

}  // namespace

extern "C" {

int carmen_map_file(const char *filename) {
  return filename != nullptr && carmen::is_map_file(filename) ? 1 : 0;
}

// Found as CARMEN's advance finds it: chunks after the one asked for are not
// read, so damage there does not hide it.
static int chunk_exists(const char *fn, const char *filename, int specific_chunk, const char *chunk_name) {
  const int rc = guarded(fn, filename, [&] {
    if (filename == nullptr) throw std::invalid_argument("no file name given");
    const std::string name = chunk_name ? chunk_name : "";
    const auto c = carmen::find_first_chunk(filename, specific_chunk, chunk_name ? &name : nullptr);
    return c ? static_cast<int>(c->size) : 0;
  });
  return rc < 0 ? 0 : rc;
}
int carmen_map_named_chunk_exists(const char *filename, int specific_chunk, const char *chunk_name) {
  return chunk_exists(__func__, filename, specific_chunk, chunk_name);
}
int carmen_map_chunk_exists(const char *filename, int specific_chunk) {
  return chunk_exists(__func__, filename, specific_chunk, nullptr);
}

// ---------------------------------------------------------------------------
// CARMEN's map-server calls (map_interface.c in CARMEN), without IPC
// ---------------------------------------------------------------------------
int carmen_map_initialize_ipc(void) {
  std::string name;
  {
    const std::lock_guard<std::mutex> lock(server_mutex);
    name = server_filename;
  }
  std::fprintf(stderr, "%s: no IPC in vasco_gpu: %s cannot be served to other processes\n", __func__,
               name.empty() ? "the map" : name.c_str());
  return -1;
}

void carmen_map_set_filename(const char *new_filename) {
  const std::lock_guard<std::mutex> lock(server_mutex);
  server_filename = new_filename ? new_filename : "";
}

void carmen_map_publish_update(void) {}

int carmen_map_advance_to_chunk(carmen_FILE *fp, int specific_chunk) {
  return advance(fp, specific_chunk, nullptr);
}

int carmen_map_advance_to_named_chunk(carmen_FILE *fp, int specific_chunk, const char *chunk_name) {
  if (chunk_name == nullptr) return -1;
  return advance(fp, specific_chunk, chunk_name);
}

}  // extern "C"
