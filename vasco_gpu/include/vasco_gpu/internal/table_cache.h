// table_cache.h — which parameters a renderer's tables were built for
// (MapperParams::table_key()), so that they are rebuilt only when the key
// changes. One cache per table set: each CPU backend and each CUDA mode
// holds one.
#ifndef VASCO_GPU_INTERNAL_TABLE_CACHE_H
#define VASCO_GPU_INTERNAL_TABLE_CACHE_H

#include <optional>
#include <utility>

#include "vasco_gpu/params.h"

namespace vasco {

class TableCache {
 public:
  // Runs build() unless the tables were built for `params`' key. The key is
  // forgotten first: a build that throws half-way (its buffers reallocated,
  // not filled) is redone by the next call instead of trusted.
  template <class Build>
  void ensure(const MapperParams &params, Build &&build) {
    MapperParams::TableKey key = params.table_key();
    if (key_ == key) return;
    key_.reset();
    std::forward<Build>(build)();
    key_ = std::move(key);
  }

 private:
  std::optional<MapperParams::TableKey> key_;
};

}  // namespace vasco

#endif  // VASCO_GPU_INTERNAL_TABLE_CACHE_H
