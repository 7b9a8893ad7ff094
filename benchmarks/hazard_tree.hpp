#pragma once
// The generated system of the verify and analyze benchmarks (`make bench-verify`, `make bench`).

#include <string>

namespace safecass::bench {

/// The scale benchmark's tree (benchmarks/bench_scale.cpp: Ck requires the Out of C((k-1)/4),
/// every Out depends on In, s_A and s_F), with hazards: each component has two Error onsets of
/// its own hazard H-k (interchangeable: the model counts them), a Warning onset of no hazard,
/// and H-k requires every child component and Ck's own Out service at Error (a leaf: itself).
inline std::string hazard_tree(int n) {
  std::string s = R"({ "safecass": 1, "system": "tree", "components": [)";
  for (int k = 0; k < n; ++k) {
    const std::string c = "C" + std::to_string(k);
    s += k ? ",\n" : "\n";
    s += R"({ "component": ")" + c + R"(", "interfaces": { "provided": ["Out"], "required": [)" + (k ? R"("In")" : "") +
         "] }";
    s += R"(, "event": [
      { "name": "EVT_)" +
         c + R"(_FAULT", "severity": 50, "state_transition": ["N2E", "W2E"], "hazard": "H-)" + std::to_string(k) +
         R"(" },
      { "name": "/EVT_)" +
         c + R"(_FAULT", "severity": 50, "state_transition": ["E2N", "E2W"] },
      { "name": "EVT_)" +
         c + R"(_OVERLOAD", "severity": 50, "state_transition": ["N2E", "W2E"], "hazard": "H-)" + std::to_string(k) +
         R"(" },
      { "name": "/EVT_)" +
         c + R"(_OVERLOAD", "severity": 50, "state_transition": ["E2N", "E2W"] },
      { "name": "EVT_)" +
         c + R"(_SLOW", "severity": 20, "state_transition": ["N2W"] },
      { "name": "/EVT_)" +
         c + R"(_SLOW", "severity": 20, "state_transition": ["W2N"] } ])";
    s += R"(, "service": [ { "name": "Out", "dependency": { "s_F": true, "s_A": true, "s_R": [)" +
         std::string(k ? R"("In")" : "") + "] } } ] }";
  }
  s += "],\n\"connections\": [";
  for (int k = 1; k < n; ++k) {
    s += k > 1 ? ",\n" : "\n";
    s += R"({ "required": "C)" + std::to_string(k) + R"(.In", "provided": "C)" + std::to_string((k - 1) / 4) +
         R"(.Out" })";
  }
  s += "],\n\"hazards\": [";
  for (int k = 0; k < n; ++k) {
    s += k ? ",\n" : "\n";
    s += R"({ "id": "H-)" + std::to_string(k) + R"(", "description": "fault of C)" + std::to_string(k) +
         R"(", "reaction": {)";
    std::string reaction;
    for (int child = 4 * k + 1; child <= 4 * k + 4 && child < n; ++child) {
      reaction += R"( "C)" + std::to_string(child) + R"(": "Error",)";
    }
    if (reaction.empty()) reaction = R"( "C)" + std::to_string(k) + R"(": "Error",)";
    s += reaction + R"( "C)" + std::to_string(k) + R"(.s_S.Out": "Error" } })";
  }
  s += "],\n\"invariants\": [ { \"name\": \"root_reaches_its_children\", "
       "\"formula\": \"[] (C0.s_A == Error -> (C1 == Error && C2 == Error && C3 == Error && C4 == Error))\" } ] }";
  return s;
}

}  // namespace safecass::bench
