#include "safecass/record/input_source.hpp"

#include <set>

#include "safecass/spec/diagnostics.hpp"

namespace safecass {

std::vector<std::string> input_signal_names(const Monitor& monitor) {
  std::set<const Signal*> outputs;
  for (const auto& f : monitor.filters()) outputs.insert(f->outputs().begin(), f->outputs().end());
  std::vector<std::string> out;
  for (const Signal* s : monitor.signals().all()) {
    if (outputs.count(s) == 0) out.push_back(s->name());
  }
  return out;
}

[[nodiscard]] Expected<Signal*> find_input_signal(Monitor& monitor, const std::string& name) {
  Signal* s = monitor.signals().find(name);
  if (s == nullptr) {
    return fail(ErrorCode::NotFound, "unknown signal '" + name + "': the system has no such signal" +
                                         spec::did_you_mean(name, input_signal_names(monitor)));
  }
  for (const auto& f : monitor.filters()) {
    for (const Signal* o : f->outputs()) {
      if (o == s) {
        return fail(ErrorCode::InvalidArgument,
                    "signal '" + name + "' is computed by filter " + f->name() + ": a log feeds input signals only");
      }
    }
  }
  return s;
}

}  // namespace safecass
