/* mapper.h — moved: the C API of the mapping session is vasco_gpu/mapper_c.h
 * (the C++ session is vasco_gpu/mapper.hpp). Kept so that existing code
 * including this name still builds. */
#include "vasco_gpu/mapper_c.h"
