// One member process's link to the bus (bus_link.hpp).

#include "bus_link.hpp"

#include <algorithm>

namespace safecass::middleware {

BusLink::BusLink(std::shared_ptr<Ice::Communicator> ic, const IceEndpoint& ice, const TlsOptions& tls,
                 BusLinkOptions options)
    : where_(to_string(ice)), options_(std::move(options)), link_(std::move(ic), ice, tls) {}

void BusLink::start() {
  if (running_.exchange(true)) return;
  sleeper_.restart();
  thread_ = std::thread([this] { loop(); });
}

void BusLink::stop() noexcept {
  running_.store(false);
  sleeper_.stop();
  if (thread_.joinable()) thread_.join();
  connected_.store(false);
}

std::shared_ptr<Ice::ObjectPrx> BusLink::publisher(std::size_t topic) const {
  std::lock_guard lock(publishers_mutex_);
  return topic < publishers_.size() ? publishers_[topic] : nullptr;
}

void BusLink::renew(const std::vector<std::string>& topics, bool quiet) {
  std::lock_guard lock(renew_mutex_);
  for (const std::string& t : topics) {
    if (std::find(renew_.begin(), renew_.end(), t) == renew_.end()) renew_.push_back(t);
    const auto q = std::find(quiet_.begin(), quiet_.end(), t);
    if (quiet && q == quiet_.end()) quiet_.push_back(t);
    if (!quiet && q != quiet_.end()) quiet_.erase(q);  // said after all
  }
}

void SentHeartbeats::sent(const wire::Signed& m) {
  std::lock_guard lock(mutex_);
  kept_[next_] = m;
  next_ = (next_ + 1) % kept_.size();
  filled_ = std::min(filled_ + 1, kept_.size());
}

bool SentHeartbeats::holds(const wire::Signed& m) const {
  std::lock_guard lock(mutex_);
  // Only slots filled: an empty message must not match one never sent.
  return std::any_of(kept_.begin(), kept_.begin() + static_cast<std::ptrdiff_t>(filled_), [&](const wire::Signed& k) {
    return k.signature == m.signature && k.body == m.body && k.signer == m.signer && k.kind == m.kind &&
           k.tags == m.tags;
  });
}

std::vector<std::string> BusLink::loud(std::vector<std::string> made) {
  std::lock_guard lock(renew_mutex_);
  std::erase_if(made, [&](const std::string& t) {
    const auto q = std::find(quiet_.begin(), quiet_.end(), t);
    if (q == quiet_.end()) return false;
    quiet_.erase(q);
    return true;
  });
  return made;
}

bool BusLink::heard_own(const wire::Signed& m) {
  if (!sent_.holds(m)) return false;
  own_heartbeat_heard();
  return true;
}

void BusLink::sleep_for(std::chrono::milliseconds d) {
  (void)sleeper_.sleep_until(steady_ns() + std::chrono::nanoseconds(d).count());
}

bool BusLink::connect() {
  try {
    link_.connect(options_.publish_on);
    {
      std::lock_guard lock(renew_mutex_);  // every subscription is under a new identity now
      renew_.clear();
      quiet_.clear();
    }
    {
      std::lock_guard lock(publishers_mutex_);
      publishers_.clear();
      for (const std::string& topic : options_.publish_on) publishers_.push_back(link_.publisher(topic));
    }
    connected_at_ = steady_ns();
    last_own_heartbeat_.store(connected_at_);
    last_beat_sent_ = 0;
    connected_.store(true);
    connects_.fetch_add(1);
    options_.log(options_.who + ": connected to IceStorm at " + where_ + "; resynchronising");
    reported_down_ = false;
    failed_connects_ = 0;
    options_.rejoined();
    return true;
  } catch (const Ice::Exception& e) {
    // Said once, then every 5 s while it lasts, so a reconnection that keeps failing shows why.
    const std::int64_t now = steady_ns();
    ++failed_connects_;
    if (!reported_down_ || now - last_down_report_ > std::chrono::nanoseconds(std::chrono::seconds(5)).count()) {
      options_.log(options_.who + ": IceStorm at " + where_ + " unreachable (" + std::string(e.ice_id()) +
                   (reported_down_ ? ", " + std::to_string(failed_connects_) + " attempts so far" : std::string()) +
                   ")" + (options_.while_down.empty() ? "" : "; " + options_.while_down) + ", retrying");
      reported_down_ = true;
      last_down_report_ = now;
    }
    return false;
  }
}

void BusLink::loop() {
  const std::chrono::milliseconds period = options_.period;
  const std::int64_t echo_bound = 5 * std::chrono::nanoseconds(period).count();
  // Typed once per connection: a proxy cast anew each period finds its connection anew (Ice shuffles
  // the endpoints for it, a random_device made each time).
  TypedPublisher<wire::HeartbeatTopicPrx> heartbeat_publisher(*this, options_.heartbeat_topic);
  while (running_.load()) {
    if (!connected_.load() && !connect()) {
      sleep_for(std::min(period, std::chrono::milliseconds(200)));
      continue;
    }
    try {
      // IceStorm is asked whether it is there only when this process's last heartbeat did not
      // come back round within a period: one that did proves the whole way works.
      // Late: the heartbeat sent a period ago has not come back (a period counted from its
      // sending: this loop's own work makes its cycle a little longer than the period).
      const bool echo_late = last_beat_sent_ != 0 && last_own_heartbeat_.load() < last_beat_sent_;
      if (echo_late) pings_.fetch_add(1);
      std::vector<std::string> renew;
      {
        std::lock_guard lock(renew_mutex_);
        renew.swap(renew_);
      }
      for (const std::string& t : renew) link_.renew(t);
      if (const std::vector<std::string> made = loud(link_.check(echo_late)); !made.empty()) {
        // What arrived on those topics meanwhile is lost: every provider republishes its state.
        options_.log(options_.who + ": " + resubscribed_line(made));
        resubscriptions_.fetch_add(made.size());
        options_.rejoined();
      }
      const wire::Signed beat = options_.heartbeat();
      sent_.sent(beat);  // before it is sent: it can come back before beat() returns
      last_beat_sent_ = steady_ns();
      heartbeat_publisher.get()->beat(beat);
      if (options_.every_period) options_.every_period();
      const std::int64_t now = steady_ns();
      if (now - connected_at_ > echo_bound && now - last_own_heartbeat_.load() > echo_bound) {
        options_.log(options_.who + ": own heartbeat did not come back; resubscribing");
        connected_.store(false);
        continue;
      }
    } catch (const Ice::Exception& e) {
      options_.log(options_.who + ": lost IceStorm (" + std::string(e.ice_id()) + ")" +
                   (options_.while_down.empty() ? "" : "; " + options_.while_down) + ", reconnecting");
      connected_.store(false);
      reported_down_ = true;
      continue;
    }
    sleep_for(period);
  }
}

}  // namespace safecass::middleware
