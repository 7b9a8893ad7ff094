// The transport's floor (`make bench-peers`, item 1): a raw IceStorm publisher and subscriber in
// two processes, no SAFECASS on either side, carrying one struct per onset and completion.
//
//   peer_icestorm_raw --ice HOST:PORT --out FILE [--samples N] [--tls DIR] [--sender-thread 1]
//
// --sender-thread 1: the thread that has the fault stamps it and hands it to a sender thread
// (a queue and a condition variable), which publishes it: what DESIGN §7 requires of SAFECASS
// (the control loop never touches the network), and so the fair floor for SAFECASS's
// visibility. Without it, the faulting thread publishes itself.
//
// --tls DIR: over mutual TLS with the certificates of a key directory (`safecass keys`), as a
// SAFECASS process runs the bus by default; the member certificate robot.pem is presented (the
// members' broker refuses the tools' reader certificate, docs/security.md).
//
// Same as bench_middleware's latency phase, on the same IceStorm: the same Ice properties as
// every SAFECASS process (middleware/src/ice_util.cpp), a oneway publisher and a oneway
// subscriber without QoS (SAFECASS's Delivery::Stream), one onset every 2 ms followed 1 ms later
// by its completion. The struct is padded to the size of the signed message SAFECASS sends for
// that onset (a StateBatch of one update with one root, in its Signed envelope), computed
// here by encoding the same content. Latency = onset time stamped just before sending → the
// subscriber's servant receiving it (the host's monotonic clock, the same in both processes).
// Writes {"p50_us", "p99_us", "max_us", "samples", "message_bytes", ...} to FILE.

#include <Ice/Ice.h>
#include <IceSSL/IceSSL.h>
#include <IceStorm/IceStorm.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <fstream>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "peers.h"
#include "safecass.h"

namespace {

using namespace std::chrono_literals;

std::int64_t now_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

/// With --tls DIR: mutual TLS as a SAFECASS process runs it, presenting DIR's member certificate
/// robot.pem (raw IceStorm over the same TLS as the system); else plain TCP.
std::string g_tls_dir;
std::string protocol() { return g_tls_dir.empty() ? "tcp" : "ssl"; }

/// The Ice properties of every SAFECASS process.
std::shared_ptr<Ice::Communicator> communicator() {
  Ice::InitializationData init;
  init.properties = Ice::createProperties();
  if (!g_tls_dir.empty()) {
    Ice::registerIceSSL(false);
    init.properties->setProperty("Ice.Plugin.IceSSL", "IceSSL:createIceSSL");
    init.properties->setProperty("IceSSL.DefaultDir", g_tls_dir);
    init.properties->setProperty("IceSSL.CAs", "ca.pem");
    init.properties->setProperty("IceSSL.CertFile", "robot.pem");
    init.properties->setProperty("IceSSL.KeyFile", "robot.key");
    init.properties->setProperty("IceSSL.VerifyPeer", "2");
    init.properties->setProperty("IceSSL.Protocols", "tls1_2, tls1_3");
  }
  init.properties->setProperty("Ice.Default.Host", "127.0.0.1");
  init.properties->setProperty("Ice.Override.ConnectTimeout", "500");
  init.properties->setProperty("Ice.Default.InvocationTimeout", "2000");
  init.properties->setProperty("Ice.RetryIntervals", "-1");
  init.properties->setProperty("Ice.Warn.Connections", "0");
  init.properties->setProperty("Ice.ThreadPool.Server.Size", "1");
  init.properties->setProperty("Ice.ThreadPool.Server.SizeMax", "1");
  init.properties->setProperty("Ice.ACM.Client.Timeout", "0");
  init.properties->setProperty("Ice.MessageSizeMax", "4096");
  return Ice::initialize(init);
}

std::shared_ptr<IceStorm::TopicPrx> fault_topic(const std::shared_ptr<Ice::Communicator>& ic, const std::string& host,
                                                int port, const std::string& name) {
  auto manager = Ice::uncheckedCast<IceStorm::TopicManagerPrx>(ic->stringToProxy(
      "SafecassIceStorm/TopicManager:" + protocol() + " -h " + host + " -p " + std::to_string(port) + " -t 2000"));
  try {
    return manager->retrieve(name);
  } catch (const IceStorm::NoSuchTopic&) {
    try {
      return manager->create(name);
    } catch (const IceStorm::TopicExists&) {
      return manager->retrieve(name);
    }
  }
}

template <class T>
std::size_t encoded_size(const std::shared_ptr<Ice::Communicator>& ic, const T& value) {
  Ice::OutputStream out(ic);
  out.write(value);
  return out.b.size();
}

/// The size of what SAFECASS sends for the onset bench_middleware measures: JR3.ForceData in
/// Error with the root EVT_FORCE_ERROR at JR3.s_A, in a signed "state" envelope (64-byte
/// Ed25519 signature), compared with a Fault without payload.
std::size_t payload_bytes(const std::shared_ptr<Ice::Communicator>& ic) {
  safecass::wire::Root root;
  root.event = "EVT_FORCE_ERROR";
  root.origin = "JR3.s_A";
  root.time = now_ns();
  root.level = safecass::wire::Level::Error;
  root.path = {"JR3.s_A", "JR3.s_S.ForceData"};
  safecass::wire::StateUpdate update;
  update.stream = 0;
  update.seq = 1;
  update.state = safecass::wire::Level::Error;
  update.roots = {root};
  update.sent = now_ns();
  Ice::OutputStream body(ic);
  body.write(safecass::wire::StateBatch{"sensor", now_ns(), 0x5afeca55, {update}});
  safecass::wire::Signed envelope;
  envelope.signer = "sensor";
  envelope.kind = "state";
  envelope.body.assign(body.b.begin(), body.b.end());
  envelope.signature.assign(64, Ice::Byte{0});
  const std::size_t whole = encoded_size(ic, envelope);
  const std::size_t bare = encoded_size(ic, peers::Fault{0, 0, true, {}});
  return whole > bare ? whole - bare : 0;
}

void write_byte(int fd, char c) { (void)!::write(fd, &c, 1); }
char read_byte(int fd) {
  char c = 0;
  return ::read(fd, &c, 1) == 1 ? c : '\0';
}

/// Publishes what the faulting thread hands it, in order (--sender-thread).
class Sender {
public:
  explicit Sender(std::shared_ptr<peers::FaultTopicPrx> pub) : pub_(std::move(pub)), thread_([this] { run(); }) {}
  ~Sender() {
    {
      std::lock_guard lock(mutex_);
      stop_ = true;
    }
    cv_.notify_one();
    thread_.join();
  }
  void send(const peers::Fault& f) {
    {
      std::lock_guard lock(mutex_);
      queue_.push_back(f);
    }
    cv_.notify_one();
  }

private:
  void run() {
    std::unique_lock lock(mutex_);
    for (;;) {
      cv_.wait(lock, [&] { return stop_ || !queue_.empty(); });
      if (queue_.empty()) return;
      peers::Fault f = std::move(queue_.front());
      queue_.pop_front();
      lock.unlock();
      pub_->fault(f);
      lock.lock();
    }
  }
  std::shared_ptr<peers::FaultTopicPrx> pub_;
  std::mutex mutex_;
  std::condition_variable cv_;
  std::deque<peers::Fault> queue_;
  bool stop_ = false;
  std::thread thread_;
};

int publisher(const std::string& host, int port, const std::string& topic_name, int in, int out, int samples,
              std::size_t payload, bool sender_thread) {
  auto ic = communicator();
  std::shared_ptr<peers::FaultTopicPrx> pub;
  try {
    auto topic = fault_topic(ic, host, port, topic_name);
    pub = Ice::uncheckedCast<peers::FaultTopicPrx>(topic->getPublisher()->ice_oneway());
  } catch (const Ice::Exception& e) {
    std::fprintf(stderr, "peer_icestorm_raw: publisher: %s\n", e.what());
    return 2;
  }
  std::optional<Sender> sender;
  if (sender_thread) sender.emplace(pub);
  const auto send = [&](const peers::Fault& f) {
    if (sender)
      sender->send(f);
    else
      pub->fault(f);
  };
  write_byte(out, 'r');
  if (read_byte(in) != 'L') return 0;
  peers::Fault f;
  f.payload.assign(payload, Ice::Byte{0x5a});
  for (int i = 0; i < samples; ++i) {
    f.seq = 2 * i;
    f.active = true;
    f.time = now_ns();
    send(f);
    std::this_thread::sleep_for(1ms);
    f.seq = 2 * i + 1;
    f.active = false;
    f.time = now_ns();
    send(f);
    std::this_thread::sleep_for(1ms);
  }
  std::this_thread::sleep_for(200ms);
  sender.reset();
  write_byte(out, 'd');
  (void)read_byte(in);
  ic->destroy();
  return 0;
}

class Subscriber final : public peers::FaultTopic {
public:
  void fault(peers::Fault f, const Ice::Current&) override {
    const std::int64_t at = now_ns();
    if (!f.active || !measuring.load()) return;
    std::lock_guard lock(mutex);
    latencies.push_back(static_cast<double>(at - f.time) / 1000.0);
    bytes = f.payload.size();
  }
  std::atomic<bool> measuring{false};
  std::mutex mutex;
  std::vector<double> latencies;
  std::size_t bytes = 0;
};

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(i, v.size() - 1)];
}

}  // namespace

int main(int argc, char** argv) {
  std::string ice_text, out_path = "peer-icestorm-raw.json";
  int samples = 2000;
  bool sender_thread = false;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--ice")
      ice_text = argv[i + 1];
    else if (key == "--out")
      out_path = argv[i + 1];
    else if (key == "--samples")
      samples = std::max(10, std::atoi(argv[i + 1]));
    else if (key == "--tls")
      g_tls_dir = argv[i + 1];
    else if (key == "--sender-thread")
      sender_thread = std::string(argv[i + 1]) == "1";
    else {
      std::fprintf(stderr, "peer_icestorm_raw: unknown option %s\n", key.c_str());
      return 2;
    }
  }
  const auto colon = ice_text.rfind(':');
  const std::string host = colon == std::string::npos ? "127.0.0.1" : ice_text.substr(0, colon);
  const int port = std::atoi(colon == std::string::npos ? ice_text.c_str() : ice_text.c_str() + colon + 1);
  if (port <= 0) {
    std::fprintf(stderr, "peer_icestorm_raw: --ice HOST:PORT is required\n");
    return 2;
  }
  std::size_t payload = 0, bare = 0;
  {
    auto ic = communicator();
    payload = payload_bytes(ic);
    bare = encoded_size(ic, peers::Fault{0, 0, true, {}});
    ic->destroy();
  }
  // A topic of this run alone (another run may share the IceStorm).
  const std::string topic_name = "peers.raw.fault." + std::to_string(::getpid());

  int to_child[2], to_parent[2];
  if (::pipe(to_child) != 0 || ::pipe(to_parent) != 0) return 2;
  const pid_t child = ::fork();
  if (child == 0) {
    ::close(to_child[1]);
    ::close(to_parent[0]);
    std::_Exit(publisher(host, port, topic_name, to_child[0], to_parent[1], samples, payload, sender_thread));
  }
  ::close(to_child[0]);
  ::close(to_parent[1]);
  struct Reap {
    pid_t pid;
    int fd;
    ~Reap() {
      ::close(fd);
      for (int i = 0; i < 300 && ::waitpid(pid, nullptr, WNOHANG) != pid; ++i) std::this_thread::sleep_for(10ms);
      ::kill(pid, SIGKILL);
      ::waitpid(pid, nullptr, WNOHANG);
    }
  } reap{child, to_child[1]};

  auto ic = communicator();
  auto servant = std::make_shared<Subscriber>();
  try {
    auto adapter = ic->createObjectAdapterWithEndpoints("RawSubscriber", protocol() + " -h 127.0.0.1");
    auto proxy = adapter->addWithUUID(servant);
    adapter->activate();
    auto topic = fault_topic(ic, host, port, topic_name);
    topic->subscribeAndGetPublisher(IceStorm::QoS{}, proxy->ice_oneway());
  } catch (const Ice::Exception& e) {
    std::fprintf(stderr, "peer_icestorm_raw: subscriber: %s\n", e.what());
    ic->destroy();
    return 1;
  }
  if (read_byte(to_parent[0]) != 'r') {
    std::fprintf(stderr, "peer_icestorm_raw: the publisher did not start\n");
    ic->destroy();
    return 1;
  }
  std::this_thread::sleep_for(300ms);
  servant->measuring.store(true);
  write_byte(to_child[1], 'L');
  const bool done = read_byte(to_parent[0]) == 'd';
  servant->measuring.store(false);
  write_byte(to_child[1], 'q');
  std::vector<double> copy;
  std::size_t bytes = 0;
  {
    std::lock_guard lock(servant->mutex);
    copy = servant->latencies;
    bytes = servant->bytes;
  }
  ic->destroy();
  const double p50 = percentile(copy, 0.50), p99 = percentile(copy, 0.99);
  const double max = copy.empty() ? 0.0 : *std::max_element(copy.begin(), copy.end());
  const std::size_t message = bytes + bare;
  char json[512];
  std::snprintf(json, sizeof json,
                "{\n  \"p50_us\": %.1f,\n  \"p99_us\": %.1f,\n  \"max_us\": %.1f,\n  \"samples\": %zu,\n"
                "  \"onsets_sent\": %d,\n  \"message_bytes\": %zu,\n  \"sender_thread\": %s,\n"
                "  \"transport\": \"raw IceStorm (icebox) on loopback, two processes, SAFECASS's Ice settings\"\n}\n",
                p50, p99, max, copy.size(), samples, message, sender_thread ? "true" : "false");
  std::ofstream(out_path) << json;
  std::printf("%s", json);
  return done && copy.size() >= static_cast<std::size_t>(samples) * 9 / 10 ? 0 : 1;
}
