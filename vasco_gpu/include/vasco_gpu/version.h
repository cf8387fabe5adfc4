#ifndef VASCO_GPU_VERSION_H
#define VASCO_GPU_VERSION_H

namespace vasco {

// The project version ("0.1.0").
const char *version();

}  // namespace vasco

#endif  // VASCO_GPU_VERSION_H
