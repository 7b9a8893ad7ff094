// The remote operations (DESIGN §6 console commands) served by every coordinator process.
// Every answer comes from the read model (introspect::LocalQuery). Reads take the coordinator's
// lock briefly; writes are refused unless the process runs with
// --allow-write and the request carries its token. A bad request changes nothing.

#include "control.hpp"

#include <mutex>

#include "read_model_wire.hpp"
#include "safecass/introspect/local_query.hpp"
#include "safecass/middleware/token.hpp"

namespace safecass::middleware {

namespace {

std::string code_text(ErrorCode c) {
  switch (c) {
    case ErrorCode::Duplicate: return "Duplicate";
    case ErrorCode::NotFound: return "NotFound";
    case ErrorCode::InvalidArgument: return "InvalidArgument";
    case ErrorCode::InvalidState: return "InvalidState";
    case ErrorCode::Io: return "Io";
    case ErrorCode::Parse: return "Parse";
    case ErrorCode::Denied: return "Denied";
  }
  return "Error";
}

[[noreturn]] void raise(const Error& e) { throw wire::OperationError(code_text(e.code), e.message); }
[[noreturn]] void raise(ErrorCode c, std::string message) { raise(Error{c, std::move(message)}); }

introspect::LocalOptions with_name(introspect::LocalOptions o, const std::string& name) {
  o.name = name;
  return o;
}

template <class T>
T value_or_raise(Expected<T> r) {
  if (!r) raise(r.error());
  return std::move(*r);
}

void ok_or_raise(const Expected<void>& r) {
  if (!r) raise(r.error());
}

/// Injected samples as the read model takes them.
std::vector<std::vector<double>> plain(wire::SampleSeq samples) {
  return {std::make_move_iterator(samples.begin()), std::make_move_iterator(samples.end())};
}

template <class Row>
auto rows_to_wire(const std::vector<Row>& rows) {
  std::vector<decltype(to_wire(rows.front()))> out;
  out.reserve(rows.size());
  for (const Row& r : rows) out.push_back(to_wire(r));
  return out;
}

/// Every answer comes from the read model (introspect::LocalQuery over this process's
/// coordinator): the servant only checks credentials and converts to the wire.
class ControlServant final : public wire::Control {
public:
  explicit ControlServant(ControlContext c)
      : c_(std::move(c)), query_(c_.co, c_.monitor, c_.registry, with_name(c_.clock, c_.name)) {}

  wire::Signed prove(wire::Bytes nonce, const Ice::Current&) override { return c_.prove(nonce); }

  std::string coordinator(const Ice::Current& current) override {
    check_read(current);
    return c_.name;
  }

  wire::StateEntrySeq stateList(std::string component, const Ice::Current& current) override {
    check_read(current);
    return rows_to_wire(value_or_raise(locked([&] { return query_.state_list(component); })));
  }

  wire::RecordEntrySeq stateHistory(std::string address, int last, const Ice::Current& current) override {
    check_read(current);
    return rows_to_wire(value_or_raise(locked([&] {
      return query_.history(address, last <= 0 ? 0 : static_cast<std::size_t>(last), introspect::HistoryFilter::All);
    })));
  }

  wire::RecordEntrySeq recordsSince(long long seq, int max, const Ice::Current& current) override {
    check_read(current);
    return rows_to_wire(value_or_raise(locked([&] {
      return query_.records_since(seq < 0 ? 0 : static_cast<std::uint64_t>(seq),
                                  max <= 0 ? 0 : static_cast<std::size_t>(max));
    })));
  }

  wire::FilterEntrySeq filterList(const Ice::Current& current) override {
    check_read(current);
    return rows_to_wire(value_or_raise(locked([&] { return query_.filter_list(); })));
  }

  wire::FilterDetails filterInfo(std::string name, const Ice::Current& current) override {
    check_read(current);
    auto info = locked([&] { return query_.filter_info(name); });
    if (!info) raise(ErrorCode::NotFound, "no filter or filter type '" + name + "' in coordinator '" + c_.name + "'");
    return to_wire(*info);
  }

  void filterInject(std::string token, std::string filter, wire::SampleSeq samples, const Ice::Current&) override {
    check_write(token, "filter inject");
    const std::size_t n = samples.size();
    apply(introspect::InjectShallow{filter, plain(std::move(samples))});
    c_.log("middleware: " + c_.name + ": filter inject " + filter + " (" + std::to_string(n) + " samples)");
  }

  void filterDinject(std::string token, std::string signal, wire::SampleSeq samples, const Ice::Current&) override {
    check_write(token, "filter dinject");
    deep(signal, std::move(samples));
  }

  wire::EventEntrySeq eventList(const Ice::Current& current) override {
    check_read(current);
    return rows_to_wire(value_or_raise(locked([&] { return query_.event_list(); })));
  }

  wire::RecordEntrySeq eventHistory(int last, const Ice::Current& current) override {
    check_read(current);
    return rows_to_wire(value_or_raise(locked([&] {
      return query_.history("SYSTEM", last <= 0 ? 0 : static_cast<std::size_t>(last),
                            introspect::HistoryFilter::Events);
    })));
  }

  void eventGenerate(std::string token, std::string event, std::string target, const Ice::Current&) override {
    check_write(token, "event generate");
    apply(introspect::GenerateEvent{event, target});
    c_.log("middleware: " + c_.name + ": event generate " + event + " " + target);
  }

  void eventBroadcast(std::string token, std::string event, const Ice::Current&) override {
    check_write(token, "event broadcast");
    apply(introspect::BroadcastEvent{event});
    c_.log("middleware: " + c_.name + ": event broadcast " + event);
  }

  wire::ConnectionEntrySeq connectionList(const Ice::Current& current) override {
    check_read(current);
    return rows_to_wire(value_or_raise(locked([&] { return query_.connection_list(); })));
  }

  wire::ServiceEntrySeq serviceList(const Ice::Current& current) override {
    check_read(current);
    return rows_to_wire(value_or_raise(locked([&] { return query_.service_list(); })));
  }

  void reset(std::string token, std::string target, std::string who, std::string why, const Ice::Current&) override {
    check_write(token, "reset");
    if (who.empty()) who = "remote";
    apply(introspect::ResetState{target, who, why});
    c_.log("middleware: " + c_.name + ": reset " + target + " by " + who + ": " + why);
  }

  wire::ExplainReply explain(std::string address, const Ice::Current& current) override {
    check_read(current);
    return to_wire(value_or_raise(locked([&] { return query_.explain(address); })));
  }

  wire::ClockEntry clockInfo(const Ice::Current& current) override {
    check_read(current);
    return to_wire(value_or_raise(locked([&] { return query_.clock(); })));
  }

  wire::NamesEntry names(const Ice::Current& current) override {
    check_read(current);
    return to_wire(value_or_raise(locked([&] { return query_.names(); })));
  }

  std::string read(std::string name, wire::Strings args, const Ice::Current& current) override {
    check_read(current);
    return value_or_raise(locked([&] { return query_.read(name, args); }));
  }

private:
  /// Reads need the read credential when the process has one (in the request context, key
  /// kReadCredentialKey); the write token is accepted too.
  void check_read(const Ice::Current& current) {
    if (c_.read_token.empty()) return;
    const auto given = current.ctx.find(kReadCredentialKey);
    if (given != current.ctx.end() &&
        (token_matches(c_.read_token, given->second) || token_matches(c_.token, given->second))) {
      return;
    }
    c_.log("middleware: " + c_.name + ": refused " + current.operation + ": no read credential");
    raise(ErrorCode::Denied,
          current.operation + " refused: coordinator '" + c_.name + "' needs its read credential (--read-token-file)");
  }

  void check_write(const std::string& token, const char* what) {
    if (!c_.allow_write) {
      c_.log("middleware: " + c_.name + ": refused " + what + ": read-only");
      raise(ErrorCode::Denied,
            std::string(what) + " refused: coordinator '" + c_.name + "' runs read-only (start it with --allow-write)");
    }
    if (!token_matches(c_.token, token)) {
      c_.log("middleware: " + c_.name + ": refused " + what + ": wrong or missing token");
      raise(ErrorCode::Denied, std::string(what) + " refused: the request does not carry coordinator '" + c_.name +
                                   "''s token (read it from its token file)");
    }
  }

  void apply(const introspect::Action& action) {
    ok_or_raise(locked([&] { return query_.apply(action); }));
  }

  void deep(const std::string& signal, wire::SampleSeq samples) {
    const std::size_t n = samples.size();
    apply(introspect::InjectDeep{signal, plain(std::move(samples))});
    c_.log("middleware: " + c_.name + ": deep injection into " + signal + " (" + std::to_string(n) + " samples)");
  }

  /// The read model is used by one thread at a time (Ice may dispatch requests on several).
  template <class F>
  auto locked(F&& f) -> decltype(f()) {
    std::lock_guard lock(mutex_);
    return f();
  }

  ControlContext c_;
  std::mutex mutex_;
  introspect::LocalQuery query_;
};

}  // namespace

std::shared_ptr<wire::Control> make_control(ControlContext context) {
  return std::make_shared<ControlServant>(std::move(context));
}

}  // namespace safecass::middleware
