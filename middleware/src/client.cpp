// RemoteClient: the console's commands as requests to a coordinator's Control object.

#include "safecass/middleware/client.hpp"

#include <condition_variable>
#include <mutex>

#include "auth.hpp"
#include "control.hpp"
#include "ice_util.hpp"
#include "safecass/middleware/keys.hpp"

namespace safecass::middleware {

using namespace detail;

namespace {

ErrorCode code_of(const std::string& text) {
  if (text == "Denied") return ErrorCode::Denied;
  if (text == "NotFound") return ErrorCode::NotFound;
  if (text == "Parse") return ErrorCode::Parse;
  if (text == "InvalidState") return ErrorCode::InvalidState;
  if (text == "Duplicate") return ErrorCode::Duplicate;
  if (text == "Io") return ErrorCode::Io;
  return ErrorCode::InvalidArgument;
}

/// Waits for an authenticated heartbeat of one coordinator and keeps its Control proxy: the
/// proxy a write token is sent to comes only from a message signed by that coordinator's key
/// (a spoofed heartbeat naming it is refused here, so the token cannot be lured elsewhere).
class Finder final : public wire::HeartbeatTopic {
public:
  Finder(std::string coordinator, const Keyring& keys, std::shared_ptr<Ice::Communicator> ic)
      : coordinator_(std::move(coordinator)), keys_(keys), ic_(std::move(ic)) {}
  void beat(wire::Signed m, const Ice::Current&) override {
    if (m.signer != coordinator_) return;  // other coordinators' heartbeats, or forgeries of them
    wire::Heartbeat h;
    std::lock_guard lock(mutex_);
    if (const std::string why = open_signed(keys_, ic_, m, kKindHeartbeat, h); !why.empty()) {
      ++refused_;
      return;
    }
    if (h.coordinator != coordinator_ || h.control.empty()) return;
    control_ = h.control;
    cv_.notify_all();
  }
  std::uint64_t refused() {
    std::lock_guard lock(mutex_);
    return refused_;
  }
  std::string wait(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    cv_.wait_for(lock, timeout, [&] { return !control_.empty(); });
    return control_;
  }

private:
  std::string coordinator_;
  const Keyring& keys_;
  std::shared_ptr<Ice::Communicator> ic_;
  std::uint64_t refused_ = 0;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::string control_;
};

HistoryRow history_row(const wire::RecordEntry& e) {
  HistoryRow r;
  r.seq = static_cast<std::uint64_t>(e.seq);
  r.time = Time{e.time};
  r.kind = e.kind;
  r.outcome = e.outcome;
  r.address = e.address;
  r.event = e.event;
  from_wire(e.from, r.from);
  from_wire(e.to, r.to);
  from_wire(e.level, r.level);
  r.mirror = e.mirror;
  r.root_event = e.rootEvent;
  r.root_origin = e.rootOrigin;
  r.text = e.text;
  return r;
}

FilterRow filter_row(const wire::FilterEntry& e) {
  return FilterRow{e.name, e.type, e.target, e.execution, e.detection, e.enabled, e.detected, e.inputs, e.outputs};
}

}  // namespace

struct RemoteClient::Impl {
  ClientOptions options;
  std::shared_ptr<Ice::Communicator> ic;
  std::shared_ptr<wire::ControlPrx> control;

  ~Impl() {
    if (ic) ic->destroy();
  }

  /// Runs one request, turning every failure into an Error.
  template <class F>
  auto call(const char* what, F&& f) -> Expected<decltype(f())> {
    try {
      if constexpr (std::is_void_v<decltype(f())>) {
        f();
        return {};
      } else {
        return f();
      }
    } catch (const wire::OperationError& e) {
      return fail(code_of(e.code), e.message);
    } catch (const Ice::Exception& e) {
      return fail(ErrorCode::Io, std::string(what) + ": coordinator '" + options.coordinator + "' did not answer (" +
                                     e.ice_id() + ")");
    }
  }
};

Expected<std::unique_ptr<RemoteClient>> RemoteClient::connect(ClientOptions options) {
  auto impl = std::make_unique<Impl>();
  impl->options = std::move(options);
  const ClientOptions& o = impl->options;
  if (impl->options.tls.enabled() && impl->options.tls.name.empty()) impl->options.tls.name = "console";
  if (auto r = check_transport("console", o.tls, o.insecure, {o.ice.host}); !r) return tl::unexpected(r.error());
  auto dir = bus_keys_dir(o.keys_dir);
  if (!dir) return tl::unexpected(dir.error());
  auto keys = Keyring::load(*dir);
  if (!keys) return tl::unexpected(keys.error());
  if (!keys->knows(o.coordinator)) {
    return fail(ErrorCode::NotFound, "coordinator '" + o.coordinator + "' has no key in " + *dir + "/keyring");
  }
  try {
    impl->ic = make_communicator(o.tls);
    auto adapter = impl->ic->createObjectAdapterWithEndpoints("SafecassClient", protocol(o.tls) + " -h 127.0.0.1");
    auto finder = std::make_shared<Finder>(o.coordinator, *keys, impl->ic);
    auto proxy = adapter->addWithUUID(finder);
    adapter->activate();
    auto heartbeat = topic(topic_manager(impl->ic, o.ice, o.tls), kHeartbeatTopic);
    subscribe(heartbeat, proxy);
    const std::string control = finder->wait(o.timeout);
    try {
      heartbeat->unsubscribe(proxy);
    } catch (const Ice::Exception&) {
    }
    adapter->destroy();
    if (control.empty()) {
      const std::uint64_t refused = finder->refused();
      return fail(ErrorCode::Io, "no authenticated heartbeat from coordinator '" + o.coordinator + "' on IceStorm " +
                                     o.ice.host + ":" + std::to_string(o.ice.port) + " within " +
                                     std::to_string(o.timeout.count()) + " ms" +
                                     (refused > 0 ? " (" + std::to_string(refused) + " forged heartbeat(s) naming it refused)" : ""));
    }
    auto prx = impl->ic->stringToProxy(control);
    // Requests and the token go in clear over TCP: only to this host, unless the endpoint is TLS
    // (mutual, with this system's CA) or the user accepts otherwise.
    for (const auto& endpoint : prx->ice_getEndpoints()) {
      auto info = endpoint->getInfo();
      const bool secure = info != nullptr && info->secure();
      while (info != nullptr && std::dynamic_pointer_cast<Ice::IPEndpointInfo>(info) == nullptr) info = info->underlying;
      const auto ip = std::dynamic_pointer_cast<Ice::IPEndpointInfo>(info);
      const bool allowed = ip != nullptr && (is_loopback_host(ip->host) || o.insecure || (secure && o.tls.enabled()));
      if (!allowed) {
        return fail(ErrorCode::Denied, "coordinator '" + o.coordinator + "' serves its operations at '" +
                                           printable(control) + "', which is not on this host and not TLS: refused "
                                           "without --insecure (requests and the token would cross the network unencrypted)");
      }
    }
    impl->control = Ice::uncheckedCast<wire::ControlPrx>(prx)->ice_invocationTimeout(static_cast<int>(o.timeout.count()));
    const std::string& credential = o.read_token.empty() ? o.token : o.read_token;
    if (!credential.empty()) impl->control = impl->control->ice_context({{kReadCredentialKey, credential}});
    impl->control->ice_ping();
  } catch (const Ice::Exception& e) {
    return fail(ErrorCode::Io, "cannot reach coordinator '" + o.coordinator + "': " + e.what());
  }
  return std::unique_ptr<RemoteClient>(new RemoteClient(std::move(impl)));
}

RemoteClient::RemoteClient(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RemoteClient::~RemoteClient() = default;

Expected<std::string> RemoteClient::coordinator() {
  return impl_->call("coordinator", [&] { return impl_->control->coordinator(); });
}

Expected<std::vector<StateRow>> RemoteClient::state_list(const std::string& component) {
  return impl_->call("state list", [&] {
    std::vector<StateRow> out;
    for (const auto& e : impl_->control->stateList(component)) {
      StateRow r{e.address, e.kind, State::Normal, e.outstanding};
      from_wire(e.state, r.state);
      out.push_back(std::move(r));
    }
    return out;
  });
}

Expected<std::vector<HistoryRow>> RemoteClient::state_history(const std::string& address, int last) {
  return impl_->call("state history", [&] {
    std::vector<HistoryRow> out;
    for (const auto& e : impl_->control->stateHistory(address, last)) out.push_back(history_row(e));
    return out;
  });
}

Expected<std::vector<FilterRow>> RemoteClient::filter_list() {
  return impl_->call("filter list", [&] {
    std::vector<FilterRow> out;
    for (const auto& e : impl_->control->filterList()) out.push_back(filter_row(e));
    return out;
  });
}

Expected<FilterDetails> RemoteClient::filter_info(const std::string& name) {
  return impl_->call("filter info", [&] {
    const wire::FilterDetails d = impl_->control->filterInfo(name);
    FilterDetails out;
    out.filter = filter_row(d.filter);
    out.doc = d.doc;
    out.missed_samples = static_cast<std::uint64_t>(d.missedSamples);
    for (const auto& p : d.params) out.params.push_back(ParamRow{p.name, p.type, p.value, p.defaultValue, p.doc});
    return out;
  });
}

Expected<void> RemoteClient::filter_inject(const std::string& filter, const std::vector<std::vector<double>>& samples) {
  return impl_->call("filter inject", [&] { impl_->control->filterInject(impl_->options.token, filter, samples); });
}

Expected<void> RemoteClient::filter_dinject(const std::string& signal, const std::vector<std::vector<double>>& samples) {
  return impl_->call("filter dinject", [&] { impl_->control->filterDinject(impl_->options.token, signal, samples); });
}

Expected<void> RemoteClient::filter_dinload(const std::string& signal, const std::string& text) {
  return impl_->call("filter dinload", [&] { impl_->control->filterDinload(impl_->options.token, signal, text); });
}

Expected<std::vector<EventRow>> RemoteClient::event_list() {
  return impl_->call("event list", [&] {
    std::vector<EventRow> out;
    for (const auto& e : impl_->control->eventList()) {
      out.push_back(EventRow{e.name, e.severity, e.onset, e.transitions, e.completes, e.latched, e.hazard, e.description});
    }
    return out;
  });
}

Expected<std::vector<HistoryRow>> RemoteClient::event_history(int last) {
  return impl_->call("event history", [&] {
    std::vector<HistoryRow> out;
    for (const auto& e : impl_->control->eventHistory(last)) out.push_back(history_row(e));
    return out;
  });
}

Expected<void> RemoteClient::generate(const std::string& event, const std::string& target) {
  return impl_->call("event generate", [&] { impl_->control->eventGenerate(impl_->options.token, event, target); });
}

Expected<void> RemoteClient::broadcast(const std::string& event) {
  return impl_->call("event broadcast", [&] { impl_->control->eventBroadcast(impl_->options.token, event); });
}

Expected<std::vector<ConnectionRow>> RemoteClient::connection_list() {
  return impl_->call("connection list", [&] {
    std::vector<ConnectionRow> out;
    for (const auto& e : impl_->control->connectionList()) out.push_back(ConnectionRow{e.required, e.provided, e.remote});
    return out;
  });
}

Expected<std::vector<ServiceRow>> RemoteClient::service_list() {
  return impl_->call("service list", [&] {
    std::vector<ServiceRow> out;
    for (const auto& e : impl_->control->serviceList()) {
      ServiceRow r{e.address, State::Normal, e.propagate, e.dependsOn};
      from_wire(e.state, r.state);
      out.push_back(std::move(r));
    }
    return out;
  });
}

Expected<void> RemoteClient::reset(const std::string& target, const std::string& who, const std::string& why) {
  return impl_->call("reset", [&] { impl_->control->reset(impl_->options.token, target, who, why); });
}

Expected<std::vector<Explanation>> RemoteClient::explain(const std::string& address) {
  return impl_->call("explain", [&] {
    std::vector<Explanation> out;
    for (const auto& e : impl_->control->explain(address)) out.push_back(detail::from_wire(e));
    return out;
  });
}

}  // namespace safecass::middleware
