#include "safecass/core/state.hpp"

#include <array>
#include <cctype>

#include "safecass/core/assert.hpp"
#include "safecass/core/observer.hpp"

#include <atomic>
#include <cstdio>
#include <cstdlib>

namespace safecass {

std::string_view to_string(State s) noexcept {
  switch (s) {
    case State::Normal: return "Normal";
    case State::Warning: return "Warning";
    case State::Error: return "Error";
  }
  return "?";
}

std::string_view to_string(Transition t) noexcept {
  static constexpr std::array<std::string_view, 6> kNames{"N2W", "N2E", "W2E", "W2N", "E2N", "E2W"};
  return kNames[static_cast<std::size_t>(t)];
}

namespace {
bool iequals(std::string_view a, std::string_view b) noexcept {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(a[i])) != std::tolower(static_cast<unsigned char>(b[i]))) return false;
  }
  return true;
}
}  // namespace

std::optional<State> parse_state(std::string_view text) noexcept {
  for (State s : {State::Normal, State::Warning, State::Error}) {
    if (iequals(text, to_string(s)) || iequals(text, to_string(s).substr(0, 1))) return s;
  }
  return std::nullopt;
}

std::optional<Transition> parse_transition(std::string_view text) noexcept {
  for (unsigned i = 0; i < 6; ++i) {
    const auto t = static_cast<Transition>(i);
    if (text == to_string(t)) return t;
  }
  return std::nullopt;
}

std::string_view to_string(RecordKind k) noexcept {
  switch (k) {
    case RecordKind::Event: return "event";
    case RecordKind::Transition: return "transition";
    case RecordKind::ComponentTransition: return "component-transition";
    case RecordKind::Reset: return "reset";
    case RecordKind::Injection: return "injection";
  }
  return "?";
}

std::string_view to_string(Outcome o) noexcept {
  switch (o) {
    case Outcome::None: return "none";
    case Outcome::Raised: return "raised";
    case Outcome::Override: return "override";
    case Outcome::Joined: return "joined";
    case Outcome::Masked: return "masked";
    case Outcome::Cleared: return "cleared";
    case Outcome::Ignored: return "ignored";
  }
  return "?";
}

std::optional<RecordKind> parse_record_kind(std::string_view text) noexcept {
  for (RecordKind k : {RecordKind::Event, RecordKind::Transition, RecordKind::ComponentTransition, RecordKind::Reset,
                       RecordKind::Injection}) {
    if (text == to_string(k)) return k;
  }
  return std::nullopt;
}

std::optional<Outcome> parse_outcome(std::string_view text) noexcept {
  for (Outcome o : {Outcome::None, Outcome::Raised, Outcome::Override, Outcome::Joined, Outcome::Masked,
                    Outcome::Cleared, Outcome::Ignored}) {
    if (text == to_string(o)) return o;
  }
  return std::nullopt;
}

namespace {
void default_fatal(const char* expression, const char* file, int line) noexcept {
  std::fprintf(stderr, "safecass: invariant failed: %s (%s:%d)\n", expression, file, line);
  std::abort();
}
std::atomic<FatalHandler> g_fatal{&default_fatal};
}  // namespace

FatalHandler set_fatal_handler(FatalHandler handler) noexcept {
  return g_fatal.exchange(handler ? handler : &default_fatal);
}

namespace detail {
void assertion_failed(const char* expression, const char* file, int line) noexcept {
  g_fatal.load()(expression, file, line);
  std::abort();  // a handler that returns still must not let execution continue
}
}  // namespace detail

}  // namespace safecass
