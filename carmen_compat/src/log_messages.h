// The table of log message types (internal to carmen_compat): one row per
// type, with its name, its field rule (what the diagnosis of a bad line
// counts) and its parser. Adding a message type is a MessageType value, its
// LogMessage member and one row in log_messages.cc.
#ifndef CARMEN_COMPAT_SRC_LOG_MESSAGES_H
#define CARMEN_COMPAT_SRC_LOG_MESSAGES_H

#include <cstddef>
#include <string_view>

#include "carmen_compat/log_reader.h"
#include "log_fields.h"

namespace carmen {

// How many fields a well-formed line of a type has after its name.
struct FieldRule {
  enum Kind {
    FIXED,       // exactly `fields`
    AT_LEAST,    // `fields` tokens or more; a shorter line lacks `needs` ("a name and a value")
    BEAMS,       // a beam count n, n ranges and more: `fields` + n in all (FLASER 10, old LASERn 4)
    BEAMS_REMISSIONS,  // 7 config fields, the beams, the remissions, then `fields` more (RAWLASER 3, ROBOTLASER 14)
  };
  Kind kind;
  int fields;
  const char *needs;  // AT_LEAST only
};

struct MessageRow;
// Parses the fields after the name into msg's member for the row's type;
// false on the first failure (recorded in f, the announced counts in c).
using MessageParser = bool (*)(const MessageRow &row, FieldParser &f, LogMessage &msg, Counts &c,
                               const char **after_host);

struct MessageRow {
  MessageType type;
  std::string_view name;  // as written in a log (a NUL-terminated literal)
  int laser_id;      // n of RAWLASERn / ROBOTLASERn; -1 for FLASER / RLASER; 0 for non-laser types
  FieldRule rule;
  MessageParser parse;
};

const MessageRow &message_row(MessageType type);

// Old "LASERn" lines: FLASER's grammar without the poses (not a row: the
// reader skips them; only readlog.h's converter reads them).
extern const FieldRule kOldLaserRule;

}  // namespace carmen

#endif  // CARMEN_COMPAT_SRC_LOG_MESSAGES_H
