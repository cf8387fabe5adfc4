// Diagnosis of a bad log line (internal to carmen_compat): why the sequential
// parse failed, in words, with the BadLine class. Structural problems (too
// few or too many fields for the counts) are reported before the field that
// tripped the parse, since a wrong count makes every later field look wrong.
#ifndef CARMEN_COMPAT_SRC_LOG_DIAGNOSIS_H
#define CARMEN_COMPAT_SRC_LOG_DIAGNOSIS_H

#include "carmen_compat/log_reader.h"
#include "log_fields.h"
#include "log_messages.h"

namespace carmen {

// Explains why `f` failed on the fields [begin, end) of a `name` line whose
// grammar is `rule`: a bad count first, then the field total, then the field
// itself. Does nothing when err is null.
void diagnose(const char *name, const FieldRule &rule, const char *begin, const char *end,
              const FieldParser &f, const Counts &c, LineError *err);

}  // namespace carmen

#endif  // CARMEN_COMPAT_SRC_LOG_DIAGNOSIS_H
