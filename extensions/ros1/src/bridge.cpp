#include "safecass/ros1/bridge.hpp"

#include <condition_variable>
#include <map>
#include <mutex>
#include <set>
#include <thread>

#include <diagnostic_msgs/DiagnosticArray.h>
#include <ros/ros.h>
#include <xmlrpcpp/XmlRpcException.h>

#include "safecass/ros1/messages.hpp"

namespace safecass::ros1 {

using ros_common::MessageType;
using ros_common::Shadow;

struct Bridge::Impl {
  std::unique_ptr<Shadow> shadow;
  bool started = false;
  std::unique_ptr<ros::NodeHandle> node_handle;
  std::vector<ros::Subscriber> subscribers;
  std::vector<ros::Timer> loop_timers;
  ros::Publisher publisher;
  ros::Subscriber ingest_subscriber;
  ros::Timer tick_timer;

  std::thread graph_thread;
  std::mutex graph_mutex;
  std::condition_variable graph_wake;
  bool graph_stop = false;

  template <class M>
  void on_message(std::size_t topic, const M& msg);
  void on_diagnostics(const ros::MessageEvent<diagnostic_msgs::DiagnosticArray const>& event);
  void on_tick();
  void publish();
  void graph_loop();
  void check_graph();
};

// ---- construction --------------------------------------------------------------------------------

Expected<std::unique_ptr<Bridge>> Bridge::create(const std::string& mapping_path, const FilterRegistry& registry,
                                                 const Clock* clock) {
  auto shadow = Shadow::create(mapping_path, registry, clock,
                               [](const std::string& text) { ROS_WARN("safecass: %s", text.c_str()); });
  if (!shadow) return tl::unexpected(shadow.error());
  auto impl = std::make_unique<Impl>();
  impl->shadow = std::move(*shadow);
  return std::unique_ptr<Bridge>(new Bridge(std::move(impl)));
}

Bridge::Bridge(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Bridge::~Bridge() { stop(); }

Coordinator& Bridge::coordinator() noexcept { return impl_->shadow->coordinator(); }
Monitor& Bridge::monitor() noexcept { return impl_->shadow->monitor(); }
const Mapping& Bridge::mapping() const noexcept { return impl_->shadow->mapping(); }
ros_common::Shadow& Bridge::shadow() noexcept { return *impl_->shadow; }
std::string Bridge::status_name(std::string_view address) const { return impl_->shadow->status_name(address); }
BridgeStats Bridge::stats() const noexcept { return impl_->shadow->stats(); }

Expected<void> Bridge::add_loop(std::string_view component, Time period, Body body) {
  return impl_->shadow->add_loop(component, period, std::move(body));
}

// ---- running -------------------------------------------------------------------------------------

Expected<void> Bridge::start() {
  Impl& d = *impl_;
  if (d.started) return fail(ErrorCode::InvalidState, "the bridge is already started");
  if (!ros::isInitialized()) return fail(ErrorCode::InvalidState, "call ros::init() before Bridge::start()");
  if (!ros::master::check()) return fail(ErrorCode::InvalidState, "no ROS master at " + ros::master::getURI());
  Shadow& sh = *d.shadow;
  d.node_handle = std::make_unique<ros::NodeHandle>();
  ros::NodeHandle& nh = *d.node_handle;
  for (std::size_t i = 0; i < sh.topic_count(); ++i) {
    const std::string& name = sh.topic(i).topic;
    const ros::TransportHints hints = ros::TransportHints().tcpNoDelay();
    switch (sh.topic(i).type) {
      case MessageType::Float64:
        d.subscribers.push_back(nh.subscribe<std_msgs::Float64>(
            name, 100, [&d, i](const std_msgs::Float64::ConstPtr& m) { d.on_message(i, *m); }, ros::VoidConstPtr(),
            hints));
        break;
      case MessageType::WrenchStamped:
        d.subscribers.push_back(nh.subscribe<geometry_msgs::WrenchStamped>(
            name, 100, [&d, i](const geometry_msgs::WrenchStamped::ConstPtr& m) { d.on_message(i, *m); },
            ros::VoidConstPtr(), hints));
        break;
      case MessageType::JointState:
        d.subscribers.push_back(nh.subscribe<sensor_msgs::JointState>(
            name, 100, [&d, i](const sensor_msgs::JointState::ConstPtr& m) { d.on_message(i, *m); },
            ros::VoidConstPtr(), hints));
        break;
    }
  }
  d.publisher = nh.advertise<diagnostic_msgs::DiagnosticArray>(sh.mapping().publish_topic, 10);
  if (sh.ingests()) {
    d.ingest_subscriber = nh.subscribe<diagnostic_msgs::DiagnosticArray>(
        sh.mapping().ingest_topic, 50,
        [&d](const ros::MessageEvent<diagnostic_msgs::DiagnosticArray const>& e) { d.on_diagnostics(e); });
  }
  for (std::size_t i = 0; i < sh.loop_count(); ++i) {
    d.loop_timers.push_back(nh.createTimer(ros::Duration(to_seconds(sh.loop_period(i))),
                                           [&sh, i](const ros::TimerEvent&) { sh.run_loop(i); }));
  }
  if (auto r = sh.start(); !r) return r;
  d.tick_timer = nh.createTimer(ros::Duration(0.02), [&d](const ros::TimerEvent&) { d.on_tick(); });
  if (sh.mapping().graph_period > 0) {
    d.graph_stop = false;
    d.graph_thread = std::thread([&d] { d.graph_loop(); });
  }
  d.started = true;
  return {};
}

void Bridge::stop() noexcept {
  Impl& d = *impl_;
  if (!d.started) return;
  {
    std::lock_guard<std::mutex> lock(d.graph_mutex);
    d.graph_stop = true;
  }
  d.graph_wake.notify_all();
  if (d.graph_thread.joinable()) d.graph_thread.join();
  d.shadow->stop();
  d.tick_timer.stop();
  for (ros::Timer& t : d.loop_timers) t.stop();
  for (ros::Subscriber& s : d.subscribers) s.shutdown();
  d.loop_timers.clear();
  d.subscribers.clear();
  d.ingest_subscriber.shutdown();
  d.publisher.shutdown();
  d.node_handle.reset();
  d.started = false;
}

template <class M>
void Bridge::Impl::on_message(std::size_t topic, const M& msg) {
  const Time now = shadow->coordinator().clock().now();
  std::string error;
  double* out = shadow->scratch(topic);
  for (const Shadow::Bound& b : shadow->bound(topic)) {
    if (!extract(b.path, msg, out, b.width, error)) {
      shadow->reject(topic, error);
      return;
    }
    out += b.width;
  }
  shadow->deliver(topic, now);
  if (shadow->take_change()) publish();  // a change made by this message's filters, at once
}

void Bridge::Impl::on_tick() {
  if (shadow->tick(shadow->coordinator().clock().now())) publish();
}

void Bridge::Impl::publish() {
  diagnostic_msgs::DiagnosticArray array;
  array.header.stamp = ros::Time::now();
  for (ros_common::Status& s : shadow->statuses()) {
    diagnostic_msgs::DiagnosticStatus out;
    out.level = static_cast<std::uint8_t>(s.level);
    out.name = std::move(s.name);
    out.message = std::move(s.message);
    out.hardware_id = std::move(s.hardware_id);
    for (auto& v : s.values) {
      diagnostic_msgs::KeyValue kv;
      kv.key = std::move(v.first);
      kv.value = std::move(v.second);
      out.values.push_back(std::move(kv));
    }
    array.status.push_back(std::move(out));
  }
  publisher.publish(array);
}

void Bridge::Impl::on_diagnostics(const ros::MessageEvent<diagnostic_msgs::DiagnosticArray const>& event) {
  if (event.getPublisherName() == ros::this_node::getName()) return;  // our own statuses
  const diagnostic_msgs::DiagnosticArray& array = *event.getConstMessage();
  std::vector<ros_common::ReceivedStatus> statuses;
  statuses.reserve(array.status.size());
  for (const diagnostic_msgs::DiagnosticStatus& s : array.status)
    statuses.push_back(ros_common::ReceivedStatus{s.name, static_cast<int>(s.level)});
  shadow->ingest(statuses, event.getPublisherName());
  if (shadow->take_change()) publish();
}

// ---- graph check ---------------------------------------------------------------------------------

void Bridge::Impl::graph_loop() {
  std::unique_lock<std::mutex> lock(graph_mutex);
  if (graph_wake.wait_for(lock, std::chrono::duration<double>(shadow->mapping().graph_grace),
                          [this] { return graph_stop; }))
    return;
  while (!graph_stop) {
    lock.unlock();
    check_graph();
    lock.lock();
    if (graph_wake.wait_for(lock, std::chrono::duration<double>(shadow->mapping().graph_period),
                            [this] { return graph_stop; }))
      return;
  }
}

void Bridge::Impl::check_graph() {
  XmlRpc::XmlRpcValue request, response, payload;
  request[0] = ros::this_node::getName();
  if (!ros::master::execute("getSystemState", request, response, payload, false)) {
    ROS_WARN_THROTTLE(10.0, "safecass: the ROS master did not answer getSystemState; graph not checked");
    return;
  }
  ros_common::GraphView live;
  try {
    for (int kind = 0; kind < payload.size() && kind < 3; ++kind) {
      for (int i = 0; i < payload[kind].size(); ++i) {
        const std::string topic = payload[kind][i][0];
        for (int j = 0; j < payload[kind][i][1].size(); ++j) {
          const std::string node = payload[kind][i][1][j];
          live.nodes.insert(node);
          if (kind == 0) live.publishers[topic].insert(node);
          if (kind == 1) live.subscribers[topic].insert(node);
        }
      }
    }
  } catch (const XmlRpc::XmlRpcException& e) {
    ROS_WARN_THROTTLE(10.0, "safecass: malformed getSystemState answer (%s); graph not checked",
                      e.getMessage().c_str());
    return;
  }
  shadow->check_graph(live);
}

}  // namespace safecass::ros1
