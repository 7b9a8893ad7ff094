#include "safecass/dds/bridge.hpp"

#include <array>
#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <thread>
#include <vector>

#include "ros2_msgs.h"
#include "safecass/dds/ros2.hpp"

namespace safecass::dds {

using ros_common::MessageNumbers;
using ros_common::MessageType;
using ros_common::Shadow;

namespace {

constexpr int kReaderDepth = 100;

std::string dds_error(const char* what, dds_return_t rc) { return std::string(what) + ": " + dds_strretcode(rc); }

MessageNumbers numbers_of(MessageType type, const void* sample) {
  MessageNumbers n;
  switch (type) {
    case MessageType::Float64: n.data = static_cast<const std_msgs_msg_dds__Float64_*>(sample)->data_; break;
    case MessageType::WrenchStamped: {
      const auto& w = static_cast<const geometry_msgs_msg_dds__WrenchStamped_*>(sample)->wrench_;
      n.wrench[0] = w.force_.x_;
      n.wrench[1] = w.force_.y_;
      n.wrench[2] = w.force_.z_;
      n.wrench[3] = w.torque_.x_;
      n.wrench[4] = w.torque_.y_;
      n.wrench[5] = w.torque_.z_;
      break;
    }
    case MessageType::JointState: {
      const auto* j = static_cast<const sensor_msgs_msg_dds__JointState_*>(sample);
      n.position = j->position_._buffer;
      n.position_size = j->position_._length;
      n.velocity = j->velocity_._buffer;
      n.velocity_size = j->velocity_._length;
      n.effort = j->effort_._buffer;
      n.effort_size = j->effort_._length;
      break;
    }
  }
  return n;
}

/// Deletes a DDS entity (and its children) when it goes out of scope.
struct Entity {
  dds_entity_t handle = 0;
  Entity() = default;
  explicit Entity(dds_entity_t h) : handle(h) {}
  Entity(Entity&& o) noexcept : handle(std::exchange(o.handle, 0)) {}
  Entity& operator=(Entity&& o) noexcept {
    reset();
    handle = std::exchange(o.handle, 0);
    return *this;
  }
  ~Entity() { reset(); }
  void reset() noexcept {
    if (handle > 0) dds_delete(handle);
    handle = 0;
  }
};

}  // namespace

struct Bridge::Impl {
  std::unique_ptr<Shadow> shadow;
  BridgeOptions options;
  int domain = -1;
  Entity participant;
  std::vector<dds_entity_t> readers;  ///< per shadow topic (children of the participant)
  dds_entity_t writer = 0;
  dds_entity_t ingest_reader = 0;
  dds_entity_t publications = 0;  ///< DCPSPublication, DCPSSubscription
  dds_entity_t subscriptions = 0;
  Entity waitset;
  std::thread thread;
  std::atomic<bool> stopping{false};
  bool started = false;

  [[nodiscard]] Expected<void> join();
  void spin();
  void take_topic(std::size_t i);
  void take_diagnostics();
  void publish(std::vector<ros_common::Status> statuses);
  void check_graph();
  /// When the spinning thread does what next (that thread only).
  using Steady = std::chrono::steady_clock;
  struct Schedule {
    Steady::time_point next_tick, next_graph;
    Steady::duration graph_period{};
    std::vector<Steady::time_point> next_loop;
    std::vector<Steady::duration> loop_period;
  };
  Schedule schedule;
  /// One pass of the spinning thread: messages, loops, the graph check, the tick.
  void step();
  /// A fault of the bridge itself: said, and EVT_THREAD_EXCEPTION on every component's s_F, so that
  /// no view stays Normal on a bridge that no longer reads.
  void fail_safe(const std::string& why);
  void warn(const std::string& text) const { options.warn(text); }
};

Expected<std::unique_ptr<Bridge>> Bridge::create(const std::string& mapping_path, const FilterRegistry& registry,
                                                 const Clock* clock, BridgeOptions options) {
  if (!options.warn)
    options.warn = [](const std::string& text) { std::fprintf(stderr, "safecass: %s\n", text.c_str()); };
  auto shadow = Shadow::create(mapping_path, registry, clock, options.warn, options.system);
  if (!shadow) return tl::unexpected(shadow.error());
  auto impl = std::make_unique<Impl>();
  impl->shadow = std::move(*shadow);
  impl->options = std::move(options);
  return std::unique_ptr<Bridge>(new Bridge(std::move(impl)));
}

Bridge::Bridge(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Bridge::~Bridge() { stop(); }

Coordinator& Bridge::coordinator() noexcept { return impl_->shadow->coordinator(); }
Monitor& Bridge::monitor() noexcept { return impl_->shadow->monitor(); }
const Mapping& Bridge::mapping() const noexcept { return impl_->shadow->mapping(); }
ros_common::Shadow& Bridge::shadow() noexcept { return *impl_->shadow; }
int Bridge::domain() const noexcept { return impl_->domain; }
BridgeStats Bridge::stats() const noexcept { return impl_->shadow->stats(); }
std::string Bridge::status_name(std::string_view address) const { return impl_->shadow->status_name(address); }

Expected<void> Bridge::add_loop(std::string_view component, Time period, Body body) {
  return impl_->shadow->add_loop(component, period, std::move(body));
}

Expected<void> Bridge::Impl::join() {
  auto joined = dds::join(options.domain, options.loopback);
  if (!joined) return tl::unexpected(joined.error());
  domain = *dds::domain_id(options.domain);
  // The domain is left to the process: deleting it would delete every participant in it, other
  // bridges' and the application's too.
  participant = Entity(joined->participant);
  const dds_entity_t pp = participant.handle;
  // The topics' readers keep more than ROS 2's default 10 samples (history depth is not matched
  // against the writer's): a burst while the spinning thread is busy must not overwrite a sample
  // before its filters judge it (the ROS 1 bridge queues 100 as well).
  dds_qos_t* qos = dds::qos(kReaderDepth);
  const Mapping& m = shadow->mapping();
  auto check = [](dds_entity_t e, const std::string& what) -> Expected<void> {
    if (e < 0) return fail(ErrorCode::Io, dds_error(what.c_str(), e));
    return {};
  };
  Expected<void> ok;
  for (std::size_t i = 0; ok && i < shadow->topic_count(); ++i) {
    const ros_common::TopicMapping& t = shadow->topic(i);
    const std::string name = dds::dds_topic(t.topic);
    const dds_entity_t topic = dds_create_topic(pp, &dds::descriptor(t.type), name.c_str(), nullptr, nullptr);
    ok = check(topic, "topic " + name);
    if (!ok) break;
    const dds_entity_t reader = dds_create_reader(pp, topic, qos, nullptr);
    ok = check(reader, "reader of " + name);
    readers.push_back(reader);
  }
  dds_delete_qos(qos);
  if (!ok) return ok;
  // Diagnostics out as diagnostic_updater, in as diagnostic_aggregator (not our own).
  const std::string out_name = dds::dds_topic(m.publish_topic);
  const dds_entity_t out =
      dds_create_topic(pp, &dds::diagnostic_array_descriptor(), out_name.c_str(), nullptr, nullptr);
  if (auto r = check(out, "topic " + out_name); !r) return r;
  qos = dds::qos(dds::kDiagnosticsWriterDepth);
  writer = dds_create_writer(pp, out, qos, nullptr);
  dds_delete_qos(qos);
  if (auto r = check(writer, "writer of " + out_name); !r) return r;
  if (shadow->ingests()) {
    const std::string in_name = dds::dds_topic(m.ingest_topic);
    const dds_entity_t in = in_name == out_name ? out
                                                : dds_create_topic(pp, &dds::diagnostic_array_descriptor(),
                                                                   in_name.c_str(), nullptr, nullptr);
    if (auto r = check(in, "topic " + in_name); !r) return r;
    qos = dds::qos(dds::kDiagnosticsReaderDepth);
    dds_qset_ignorelocal(qos, DDS_IGNORELOCAL_PARTICIPANT);
    ingest_reader = dds_create_reader(pp, in, qos, nullptr);
    dds_delete_qos(qos);
    if (auto r = check(ingest_reader, "reader of " + in_name); !r) return r;
  }
  if (m.graph_period > 0) {
    publications = dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSPUBLICATION, nullptr, nullptr);
    if (auto r = check(publications, "DCPSPublication reader"); !r) return r;
    subscriptions = dds_create_reader(pp, DDS_BUILTIN_TOPIC_DCPSSUBSCRIPTION, nullptr, nullptr);
    if (auto r = check(subscriptions, "DCPSSubscription reader"); !r) return r;
  }
  waitset = Entity(dds_create_waitset(pp));
  if (auto r = check(waitset.handle, "waitset"); !r) return r;
  for (std::size_t i = 0; i < readers.size(); ++i) {
    dds_set_status_mask(readers[i], DDS_DATA_AVAILABLE_STATUS);
    dds_waitset_attach(waitset.handle, readers[i], static_cast<dds_attach_t>(i));
  }
  if (ingest_reader > 0) {
    dds_set_status_mask(ingest_reader, DDS_DATA_AVAILABLE_STATUS);
    dds_waitset_attach(waitset.handle, ingest_reader, static_cast<dds_attach_t>(readers.size()));
  }
  return {};
}

Expected<void> Bridge::start() {
  Impl& d = *impl_;
  if (d.started) return fail(ErrorCode::InvalidState, "the bridge is already started");
  if (auto r = d.join(); !r) {
    d.waitset.reset();
    d.participant.reset();
    d.readers.clear();
    return r;
  }
  if (auto r = d.shadow->start(); !r) return r;
  d.stopping = false;
  d.thread = std::thread([&d] { d.spin(); });
  d.started = true;
  return {};
}

void Bridge::stop() noexcept {
  Impl& d = *impl_;
  if (!d.started) return;
  d.stopping = true;
  dds_waitset_set_trigger(d.waitset.handle, true);
  if (d.thread.joinable()) d.thread.join();
  d.shadow->stop();
  d.waitset.reset();
  d.participant.reset();  // deletes the readers, writer and topics
  d.readers.clear();
  d.writer = d.ingest_reader = d.publications = d.subscriptions = 0;
  d.started = false;
}

// ---- the spinning thread -------------------------------------------------------------------------

void Bridge::Impl::spin() {
  const auto begin = Steady::now();
  Schedule& at = schedule;
  at.next_tick = begin;
  at.next_graph = begin + std::chrono::duration_cast<Steady::duration>(
                              std::chrono::duration<double>(shadow->mapping().graph_grace));
  at.graph_period =
      std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(shadow->mapping().graph_period));
  at.next_loop.assign(shadow->loop_count(), begin);
  at.loop_period.clear();
  for (std::size_t i = 0; i < shadow->loop_count(); ++i)
    at.loop_period.push_back(std::chrono::duration_cast<Steady::duration>(shadow->loop_period(i)));

  while (!stopping.load(std::memory_order_acquire)) {
    auto wake = at.next_tick;
    for (const auto& t : at.next_loop) wake = std::min(wake, t);
    if (publications > 0) wake = std::min(wake, at.next_graph);
    const auto wait = std::max(Steady::duration::zero(), wake - Steady::now());
    const dds_return_t rc = dds_waitset_wait(waitset.handle, nullptr, 0,
                                             std::chrono::duration_cast<std::chrono::nanoseconds>(wait).count());
    if (stopping.load(std::memory_order_acquire)) break;
    if (rc < 0) {  // the DDS entities are gone (deleted from elsewhere): nothing more can be read
      fail_safe(dds_error("DDS waitset", rc) + "; the bridge stops reading");
      return;
    }
    try {
      step();
    } catch (const std::exception& e) {
      fail_safe(std::string("the bridge's thread: ") + e.what());
    }
  }
}

void Bridge::Impl::fail_safe(const std::string& why) {
  warn(why);
  Coordinator& co = shadow->coordinator();
  for (ComponentId c : id_range<ComponentId>(co.structure().component_count()))
    co.generate(framework_event::kThreadException, co.structure().framework_machine(c));
}

void Bridge::Impl::step() {
  constexpr auto kTick = std::chrono::milliseconds(20);
  Schedule& at = schedule;
  for (std::size_t i = 0; i < readers.size(); ++i) take_topic(i);
  if (ingest_reader > 0) take_diagnostics();
  // A change made by a message (its ACTIVE filters, an ingested status) is published at once.
  if (shadow->take_change()) publish(shadow->statuses());
  const auto now = Steady::now();
  for (std::size_t i = 0; i < at.next_loop.size(); ++i) {
    if (now < at.next_loop[i]) continue;
    shadow->run_loop(i);
    at.next_loop[i] += at.loop_period[i];
    if (at.next_loop[i] < now) at.next_loop[i] = now + at.loop_period[i];  // overran: no burst of catch-up cycles
  }
  if (publications > 0 && now >= at.next_graph) {
    check_graph();
    at.next_graph = now + at.graph_period;
  }
  if (now >= at.next_tick) {
    if (shadow->tick(shadow->coordinator().clock().now())) publish(shadow->statuses());
    at.next_tick += kTick;
    if (at.next_tick < now) at.next_tick = now + kTick;
  }
}

void Bridge::Impl::take_topic(std::size_t i) {
  constexpr std::size_t kBatch = 16;
  const MessageType type = shadow->topic(i).type;
  std::array<void*, kBatch> samples{};
  std::array<dds_sample_info_t, kBatch> infos{};
  std::string error;
  for (;;) {
    samples.fill(nullptr);
    const dds_return_t n = dds_take(readers[i], samples.data(), infos.data(), kBatch, kBatch);
    if (n <= 0) return;
    for (dds_return_t k = 0; k < n; ++k) {
      if (!infos[static_cast<std::size_t>(k)].valid_data) continue;
      const MessageNumbers numbers = numbers_of(type, samples[static_cast<std::size_t>(k)]);
      double* out = shadow->scratch(i);
      bool good = true;
      for (const Shadow::Bound& b : shadow->bound(i)) {
        if (!ros_common::extract(b.path, numbers, out, b.width, error)) {
          shadow->reject(i, error);
          good = false;
          break;
        }
        out += b.width;
      }
      if (good) shadow->deliver(i, shadow->coordinator().clock().now());
    }
    dds_return_loan(readers[i], samples.data(), n);
    if (static_cast<std::size_t>(n) < kBatch) return;
  }
}

void Bridge::Impl::take_diagnostics() {
  constexpr std::size_t kBatch = 8;
  std::array<void*, kBatch> samples{};
  std::array<dds_sample_info_t, kBatch> infos{};
  std::vector<ros_common::ReceivedStatus> statuses;
  for (;;) {
    samples.fill(nullptr);
    const dds_return_t n = dds_take(ingest_reader, samples.data(), infos.data(), kBatch, kBatch);
    if (n <= 0) return;
    for (dds_return_t k = 0; k < n; ++k) {
      if (!infos[static_cast<std::size_t>(k)].valid_data) continue;
      const auto* array =
          static_cast<const diagnostic_msgs_msg_dds__DiagnosticArray_*>(samples[static_cast<std::size_t>(k)]);
      statuses.clear();
      for (std::uint32_t s = 0; s < array->status_._length; ++s) {
        const diagnostic_msgs_msg_dds__DiagnosticStatus_& st = array->status_._buffer[s];
        statuses.push_back(ros_common::ReceivedStatus{st.name_ != nullptr ? st.name_ : "", st.level_});
      }
      char sender[40];
      std::snprintf(sender, sizeof sender, "writer %016llx",
                    static_cast<unsigned long long>(infos[static_cast<std::size_t>(k)].publication_handle));
      shadow->ingest(statuses, sender);
    }
    dds_return_loan(ingest_reader, samples.data(), n);
    if (static_cast<std::size_t>(n) < kBatch) return;
  }
}

void Bridge::Impl::publish(std::vector<ros_common::Status> statuses) {
  // The sample points into `statuses`; dds_write() serialises it before returning.
  std::vector<diagnostic_msgs_msg_dds__DiagnosticStatus_> out(statuses.size());
  std::vector<std::vector<diagnostic_msgs_msg_dds__KeyValue_>> values(statuses.size());
  for (std::size_t i = 0; i < statuses.size(); ++i) {
    ros_common::Status& s = statuses[i];
    for (auto& kv : s.values) values[i].push_back({kv.first.data(), kv.second.data()});
    out[i].level_ = static_cast<std::uint8_t>(s.level);
    out[i].name_ = s.name.data();
    out[i].message_ = s.message.data();
    out[i].hardware_id_ = s.hardware_id.data();
    out[i].values_._length = out[i].values_._maximum = static_cast<std::uint32_t>(values[i].size());
    out[i].values_._buffer = values[i].data();
    out[i].values_._release = false;
  }
  diagnostic_msgs_msg_dds__DiagnosticArray_ array{};
  const auto wall = std::chrono::system_clock::now().time_since_epoch();
  const auto ns = std::chrono::duration_cast<std::chrono::nanoseconds>(wall).count();
  array.header_.stamp_.sec_ = static_cast<std::int32_t>(ns / 1000000000);
  array.header_.stamp_.nanosec_ = static_cast<std::uint32_t>(ns % 1000000000);
  char empty[] = "";
  array.header_.frame_id_ = empty;
  array.status_._length = array.status_._maximum = static_cast<std::uint32_t>(out.size());
  array.status_._buffer = out.data();
  array.status_._release = false;
  if (const dds_return_t rc = dds_write(writer, &array); rc < 0) warn(dds_error("diagnostics not published", rc));
}

void Bridge::Impl::check_graph() {
  ros_common::GraphView live;
  live.nodes_known = false;
  dds_guid_t self{};
  dds_get_guid(participant.handle, &self);
  constexpr std::size_t kMax = 1024;
  std::vector<void*> samples(kMax);
  std::vector<dds_sample_info_t> infos(kMax);
  for (const dds_entity_t reader : {publications, subscriptions}) {
    std::fill(samples.begin(), samples.end(), nullptr);
    const dds_return_t n = dds_read_mask(reader, samples.data(), infos.data(), kMax, kMax,
                                         DDS_ANY_SAMPLE_STATE | DDS_ANY_VIEW_STATE | DDS_ALIVE_INSTANCE_STATE);
    if (n < 0) {
      // Not knowing the graph is not a complete graph: every mapped interface is reported missing.
      warn(dds_error("DDS discovery not read; every mapped endpoint counts as missing", n));
      shadow->check_graph(ros_common::GraphView{false, {}, {}, {}, {}});
      return;
    }
    auto& endpoints = reader == publications ? live.publishers : live.subscribers;
    for (dds_return_t k = 0; k < n; ++k) {
      if (!infos[static_cast<std::size_t>(k)].valid_data) continue;
      const auto* e = static_cast<const dds_builtintopic_endpoint_t*>(samples[static_cast<std::size_t>(k)]);
      if (e->topic_name == nullptr || e->type_name == nullptr) continue;
      const auto topic = dds::ros_topic(e->topic_name);
      if (!topic) continue;
      for (std::size_t i = 0; i < shadow->topic_count(); ++i) {
        if (shadow->topic(i).topic != *topic) continue;
        if (e->type_name == dds::dds_type(shadow->topic(i).type)) {
          // The bridge's own readers are not a ROS node's subscription (GraphView::kSelf).
          endpoints[*topic].insert(std::memcmp(&e->participant_key, &self, sizeof self) == 0
                                       ? std::string(ros_common::GraphView::kSelf)
                                       : std::string());
        } else if (reader == publications) {
          live.mistyped[*topic].insert(e->type_name);
        }
      }
    }
    if (n > 0) dds_return_loan(reader, samples.data(), n);
  }
  shadow->check_graph(live);
}

}  // namespace safecass::dds
