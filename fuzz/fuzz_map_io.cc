// CARMEN's C map API on arbitrary files: every chunk reader, plain and
// named, must return 0 or -1, never crash, hang or leak what it allocated.
#include <cstdlib>
#include <ctime>

#include "carmen/map_io.h"
#include "carmen_map_free.h"
#include "fuzz_support.h"

namespace {

using maptest::free_hmap;
using maptest::free_map;

void read_everything(const char *file, const char *name) {
  carmen_map_t map{};
  if ((name ? carmen_map_read_named_gridmap_chunk(file, name, &map) : carmen_map_read_gridmap_chunk(file, &map)) == 0)
    free_map(map);
  carmen_map_config_t config{};
  if ((name ? carmen_map_read_named_gridmap_config(file, name, &config) : carmen_map_read_gridmap_config(file, &config)) == 0)
    std::free(config.map_name);
  carmen_map_placelist_t places{};
  if ((name ? carmen_map_read_named_places_chunk(file, name, &places) : carmen_map_read_places_chunk(file, &places)) == 0)
    std::free(places.places);
  carmen_offlimits_p offlimits = nullptr;
  int count = 0;
  if ((name ? carmen_map_read_named_offlimits_chunk(file, name, &offlimits, &count)
            : carmen_map_read_offlimits_chunk(file, &offlimits, &count)) == 0)
    std::free(offlimits);
  carmen_laser_scan_p scans = nullptr;
  if ((name ? carmen_map_read_named_laserscans_chunk(file, name, &scans, &count)
            : carmen_map_read_laserscans_chunk(file, &scans, &count)) == 0) {
    for (int i = 0; i < count; ++i) std::free(scans[i].range);
    std::free(scans);
  }
  carmen_global_offset_t offset{};
  if (name) carmen_map_read_named_global_offset_chunk(file, name, &offset);
  else carmen_map_read_global_offset_chunk(file, &offset);
  time_t when = 0;
  char user[16], origin[96], description[96];
  if (name) carmen_map_read_named_creator_chunk(file, name, &when, user, origin, description);
  else carmen_map_read_creator_chunk(file, &when, user, origin, description);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size) {
  for (const char *suffix : {".map", ".map.gz"}) {
    fuzz::InputFile in(data, size, suffix);
    const char *file = in.path().c_str();
    read_everything(file, nullptr);
    read_everything(file, "zone");
    carmen_hmap_t hmap{};
    if (carmen_map_read_hmap_chunk(file, &hmap) == 0) free_hmap(hmap);
    carmen_map_file(file);
    carmen_map_chunk_exists(file, CARMEN_MAP_GRIDMAP_CHUNK);
  }
  return 0;
}
