// A live system over the bus (docs/python.md, "A live system"): one coordinator process reached
// through the middleware's RemoteClient, as `safecass console --ice` reaches it, with the reader's
// certificate and the keyring (and the read token when the system has one); writes need the
// coordinator's write token. Every request waits for its answer with the GIL released.
#include <chrono>
#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include <pybind11/stl.h>

#include "bindings.hpp"
#include "query_methods.hpp"

#ifdef SAFECASS_PYTHON_WITH_BUS
#include "safecass/middleware/client.hpp"
#include "safecass/middleware/token.hpp"
#endif

namespace safecass::python {

#ifdef SAFECASS_PYTHON_WITH_BUS

namespace in = safecass::introspect;

namespace {

/// The records of a followed coordinator, queued by the follower's thread for a Python iterator.
class RecordQueue {
public:
  void push(const in::HistoryEntry& e) {
    {
      const std::lock_guard lock(mutex_);
      records_.push_back(e);
    }
    ready_.notify_one();
  }
  /// The next record, or none when `timeout` passes first.
  std::optional<in::HistoryEntry> pop(std::chrono::milliseconds timeout) {
    std::unique_lock lock(mutex_);
    if (!ready_.wait_for(lock, timeout, [this] { return !records_.empty(); })) return std::nullopt;
    in::HistoryEntry e = std::move(records_.front());
    records_.pop_front();
    return e;
  }

private:
  std::mutex mutex_;
  std::condition_variable ready_;
  std::deque<in::HistoryEntry> records_;
};

class RemoteSystem {
public:
  static std::unique_ptr<RemoteSystem> connect(middleware::ClientOptions options) {
    Expected<std::unique_ptr<middleware::RemoteClient>> client = fail(ErrorCode::Io, "not connected");
    {
      py::gil_scoped_release unlocked;
      client = middleware::RemoteClient::connect(std::move(options));
    }
    auto remote = std::make_unique<RemoteSystem>();
    remote->client_ = value_or_raise(std::move(client));
    return remote;
  }

  template <class Read>
  auto ask(Read read) {
    open_or_raise();
    std::optional<decltype(read(*client_))> answer;
    {
      py::gil_scoped_release unlocked;
      const std::lock_guard lock(busy_);
      answer.emplace(read(*client_));
    }
    return value_or_raise(std::move(*answer));
  }

  void apply(const in::Action& action) {
    ask([&](in::SystemQuery& q) { return q.apply(action); });
  }

  /// Starts following the coordinator's records, once: every record from now on is queued.
  void follow() {
    open_or_raise();
    if (!following_) {
      auto queue = std::make_shared<RecordQueue>();
      following_ =
          ask([&](in::SystemQuery& q) { return q.follow([queue](const in::HistoryEntry& e) { queue->push(e); }); });
      queue_ = std::move(queue);
    }
  }

  /// The next record followed, or None after `timeout` seconds without one.
  std::optional<in::HistoryEntry> next_record(double timeout) {
    follow();
    const auto wait = std::chrono::milliseconds(static_cast<long long>(std::max(0.0, timeout) * 1000.0));
    py::gil_scoped_release unlocked;
    return queue_->pop(wait);
  }

  std::string name() const { return client_ ? client_->name() : std::string(); }

  void close() {
    py::gil_scoped_release unlocked;
    const std::lock_guard lock(busy_);
    following_.reset();
    client_.reset();
  }

private:
  void open_or_raise() const {
    if (!client_) raise(Error{ErrorCode::InvalidState, "this connection is closed"});
  }

  std::mutex busy_;
  std::unique_ptr<middleware::RemoteClient> client_;
  std::unique_ptr<in::Subscription> following_;
  std::shared_ptr<RecordQueue> queue_;
};

std::string token_from(const std::string& file) {
  if (file.empty()) return {};
  return value_or_raise(middleware::read_token_file(file));
}

}  // namespace

void bind_remote(py::module_& m) {
  py::class_<RemoteSystem> c(m, "RemoteSystem", "A live coordinator process, reached over the bus.");
  c.def_property_readonly("name", &RemoteSystem::name, "the coordinator's name")
      .def("_follow", &RemoteSystem::follow)
      .def("_next_record", &RemoteSystem::next_record, py::arg("timeout"))
      .def("close", &RemoteSystem::close, "Leaves the bus (the coordinator is not touched).")
      .def("__enter__", [](RemoteSystem& s) -> RemoteSystem& { return s; })
      .def("__exit__", [](RemoteSystem& s, const py::args&) { s.close(); });
  bind_actions(c);
  bind_reads(c);
  m.def(
      "connect",
      [](const std::string& ice, const std::string& coordinator, const std::string& keys,
         const std::string& read_token_file, const std::string& token_file, const std::string& tls, double timeout) {
        auto endpoint = middleware::parse_ice_endpoint(ice);
        if (!endpoint) raise(endpoint.error());
        middleware::ClientOptions o;
        o.ice = *endpoint;
        o.coordinator = coordinator;
        o.keys_dir = keys;
        o.read_token = token_from(read_token_file);
        o.token = token_from(token_file);
        o.tls.dir = tls;
        o.timeout = std::chrono::milliseconds(static_cast<long long>(timeout * 1000.0));
        return RemoteSystem::connect(std::move(o));
      },
      py::arg("ice"), py::arg("coordinator"), py::arg("keys") = "", py::arg("read_token") = "", py::arg("token") = "",
      py::arg("tls") = "", py::arg("timeout") = 2.0,
      "Connects to a live coordinator as `safecass console --ice HOST:PORT --coordinator NAME` does: found by its "
      "signed heartbeat on IceStorm and proven alive before anything is sent. keys: the system's bus keys "
      "(default $SAFECASS_KEYS); read_token, token: the read and write token files (token: writes allowed).");
}

#else

void bind_remote(py::module_& m) {
  m.def("connect", [](const py::args&, const py::kwargs&) {
    raise(Error{ErrorCode::InvalidState, "this build has no middleware (SAFECASS_WITH_ICE=OFF)"});
  });
}

#endif

}  // namespace safecass::python
