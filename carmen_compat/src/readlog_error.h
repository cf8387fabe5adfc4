// readlog_error.h — the text carmen_readlog_last_error() returns, per thread,
// shared by the index (readlog.cc) and the converters (readlog_messages.cc):
// each call clears it and sets it where it fails.
#ifndef CARMEN_COMPAT_READLOG_ERROR_H
#define CARMEN_COMPAT_READLOG_ERROR_H

#include <string>

namespace carmen {

std::string &readlog_error_text();

}  // namespace carmen

#endif  // CARMEN_COMPAT_READLOG_ERROR_H
