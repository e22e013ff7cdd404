#include "scfloam/loop/loop_candidate.hpp"

#include "scfloam/error.hpp"

namespace scfloam {

std::string to_string(LoopVerdict verdict) {
  switch (verdict) {
    case LoopVerdict::kAccepted: return "accepted";
    case LoopVerdict::kRejectedScore: return "rejected_score";
    case LoopVerdict::kRejectedGate: return "rejected_gate";
    case LoopVerdict::kRejectedRank: return "rejected_rank";
    case LoopVerdict::kRejectedMatch: return "rejected_match";
  }
  return "unknown";
}

LoopVerdict parse_loop_verdict(const std::string& name) {
  for (LoopVerdict v : {LoopVerdict::kAccepted, LoopVerdict::kRejectedScore, LoopVerdict::kRejectedGate,
                        LoopVerdict::kRejectedRank, LoopVerdict::kRejectedMatch})
    if (to_string(v) == name) return v;
  throw Error("unknown loop verdict '" + name + "'");
}

}  // namespace scfloam
