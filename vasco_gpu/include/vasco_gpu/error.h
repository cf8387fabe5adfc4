// error.h — vasco::Error: the engine's errors carry a code (carmen_compat's
// ErrorCode; the engine sits on carmen_compat, so there is one type).
//
//   try { mapper.insert(scans); }
//   catch (const vasco::Error &e) { if (e.code() == vasco::ErrorCode::OutOfMemory) ... }
#ifndef VASCO_GPU_ERROR_H
#define VASCO_GPU_ERROR_H

#include "carmen_compat/error.h"

namespace vasco {

using carmen::Error;
using carmen::ErrorCode;
using carmen::FileError;
using carmen::error_code_name;

}  // namespace vasco

#endif  // VASCO_GPU_ERROR_H
