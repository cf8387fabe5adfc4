// log_odds.h — a probability's log-odds, as the float backends sum evidence.
#ifndef VASCO_GPU_LOG_ODDS_H
#define VASCO_GPU_LOG_ODDS_H

#include <cmath>

namespace vasco {

// log(p / (1 - p)); +-inf at exactly 1 and 0 (the oracle's pinned cells).
inline double logit(double p) { return std::log(p / (1.0 - p)); }

}  // namespace vasco

#endif  // VASCO_GPU_LOG_ODDS_H
