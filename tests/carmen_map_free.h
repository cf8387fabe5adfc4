// Frees what CARMEN's C map readers allocate inside a carmen_map_t or a
// carmen_hmap_t (CARMEN has no function for it): shared by the map API tests
// and the map API fuzz target, which must leave nothing behind.
#ifndef VASCO_TESTS_CARMEN_MAP_FREE_H
#define VASCO_TESTS_CARMEN_MAP_FREE_H

#include <cstdlib>

#include "carmen/map_io.h"

namespace maptest {

inline void free_map(carmen_map_t &m) {
  std::free(m.map);
  std::free(m.complete_map);
  std::free(m.config.map_name);
}

inline void free_hmap(carmen_hmap_t &h) {
  for (int i = 0; i < h.num_zones; ++i) std::free(h.zone_names[i]);
  for (int i = 0; i < h.num_links; ++i) {
    std::free(h.links[i].keys);
    std::free(h.links[i].points);
  }
  std::free(h.zone_names);
  std::free(h.links);
}

}  // namespace maptest

#endif  // VASCO_TESTS_CARMEN_MAP_FREE_H
