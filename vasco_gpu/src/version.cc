#include "vasco_gpu/version.h"

namespace vasco {

const char *version() { return VASCO_GPU_VERSION; }

}  // namespace vasco
