// A ROS 1 bag as a replay source. C++17: Debian's ROS message headers do not compile as C++20.

#include "safecass/replay/bag_source.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <deque>
#include <set>

#include "extract.hpp"
#include "safecass/ros_common/mapping.hpp"

namespace safecass::replay {

namespace {

struct Binding {
  Signal* signal;
  ros_common::FieldPath path;
  std::size_t width;
};

struct Topic {
  ros_common::TopicMapping mapping;
  std::vector<Binding> bindings;
};

class BagSource final : public InputSource {
public:
  BagSource(std::string path, ros_common::Mapping mapping) : path_(std::move(path)), mapping_(std::move(mapping)) {}

  [[nodiscard]] Expected<void> open() {
    try {
      bag_.open(path_, rosbag::bagmode::Read);
      rosbag::View all(bag_);
      begin_ = all.getBeginTime();
    } catch (const std::exception& e) {
      return fail(ErrorCode::Parse, path_ + ": not a readable ROS bag (truncated or damaged?): " + e.what());
    }
    return {};
  }

  [[nodiscard]] Expected<void> bind(Monitor& monitor) override {
    std::vector<std::string> topics;
    for (const ros_common::TopicMapping& t : mapping_.topics) {
      Topic topic{t, {}};
      for (const ros_common::FieldBinding& b : t.signals) {
        Signal* s = monitor.signals().find(b.signal);
        if (s == nullptr) {
          skipped_.insert(b.signal + " (" + t.topic + " " + b.path.text + ")");
          continue;
        }
        auto input = find_input_signal(monitor, b.signal);
        if (!input) return fail(ErrorCode::Parse, mapping_.path + ": topic " + t.topic + ": " + input.error().message);
        const std::size_t width = b.path.width() == 0 ? s->size() : b.path.width();
        if (width != s->size()) {
          return fail(ErrorCode::Parse, mapping_.path + ": topic " + t.topic + ": path '" + b.path.text + "' reads " +
                                            std::to_string(width) + " values; signal '" + b.signal + "' has size " +
                                            std::to_string(s->size()));
        }
        topic.bindings.push_back(Binding{s, b.path, width});
      }
      if (!topic.bindings.empty()) {
        topics.push_back(t.topic);
        topics_.push_back(std::move(topic));
      }
    }
    if (topics_.empty()) {
      return fail(ErrorCode::Parse, mapping_.path + ": no topic of the mapping feeds a signal of the system");
    }
    try {
      view_ = std::make_unique<rosbag::View>(bag_, rosbag::TopicQuery(topics));
      it_ = view_->begin();
    } catch (const std::exception& e) {
      return fail(ErrorCode::Parse, path_ + ": cannot read the bag: " + e.what());
    }
    return {};
  }

  Item next() override {
    Item item;
    if (failed_) {
      item.kind = Item::Kind::Error;
      return item;
    }
    while (pending_.empty()) {
      try {
        if (it_ == view_->end()) {
          item.kind = Item::Kind::End;
          return item;
        }
        ++index_;
        const rosbag::MessageInstance& m = *it_;
        if (!read(m)) {
          item.kind = Item::Kind::Error;
          return item;
        }
        ++it_;
      } catch (const std::exception& e) {
        failed_ = true;
        error_ = path_ + ": message " + std::to_string(index_) +
                 ": the bag is truncated or damaged (rosbag: " + e.what() + ")";
        item.kind = Item::Kind::Error;
        return item;
      }
    }
    const Pending& p = pending_.front();
    current_.assign(values_.begin() + static_cast<std::ptrdiff_t>(p.offset),
                    values_.begin() + static_cast<std::ptrdiff_t>(p.offset + p.signal->size()));
    item.kind = Item::Kind::Sample;
    item.time = p.time;
    item.signal = p.signal;
    item.values = current_.data();
    pending_.pop_front();
    if (pending_.empty()) values_.clear();
    ++samples_;
    return item;
  }

  const std::string& error() const override { return error_; }
  std::uint64_t samples() const override { return samples_; }
  std::string where() const override { return path_ + ": message " + std::to_string(index_); }
  std::vector<std::string> notes() const override {
    std::vector<std::string> out;
    for (const std::string& s : skipped_)
      out.push_back(path_ + ": mapped signal " + s + " is not in the system: not fed");
    return out;
  }

private:
  struct Pending {
    Time time;
    Signal* signal;
    std::size_t offset;
  };

  bool fail_message(const std::string& topic, const std::string& reason) {
    failed_ = true;
    error_ = path_ + ": message " + std::to_string(index_) + " (" + topic + "): " + reason;
    return false;
  }

  template <class Msg>
  bool extract_all(const Topic& t, const Msg& msg, Time time) {
    for (const Binding& b : t.bindings) {
      const std::size_t at = values_.size();
      values_.resize(at + b.width);
      std::string why;
      if (!ros1::detail::extract(b.path, msg, values_.data() + at, b.width, why))
        return fail_message(t.mapping.topic, why);
      pending_.push_back(Pending{time, b.signal, at});
    }
    return true;
  }

  bool read(const rosbag::MessageInstance& m) {
    const Topic* t = nullptr;
    for (const Topic& candidate : topics_) {
      if (candidate.mapping.topic == m.getTopic()) t = &candidate;
    }
    if (t == nullptr) return true;
    const ros::Duration since = m.getTime() - begin_;
    const Time time{since.toNSec()};
    const std::string expected(ros_common::to_string(t->mapping.type));
    if (m.getDataType() != expected) {
      return fail_message(t->mapping.topic, "a " + m.getDataType() + " message; the mapping says " + expected);
    }
    try {
      switch (t->mapping.type) {
        case ros_common::MessageType::Float64: return extract_all(*t, *m.instantiate<std_msgs::Float64>(), time);
        case ros_common::MessageType::WrenchStamped:
          return extract_all(*t, *m.instantiate<geometry_msgs::WrenchStamped>(), time);
        case ros_common::MessageType::JointState:
          return extract_all(*t, *m.instantiate<sensor_msgs::JointState>(), time);
      }
    } catch (const std::exception& e) {
      return fail_message(t->mapping.topic, "cannot be read as " + expected + " (rosbag: " + e.what() + ")");
    }
    return true;
  }

  std::string path_;
  ros_common::Mapping mapping_;
  rosbag::Bag bag_;
  ros::Time begin_;
  std::unique_ptr<rosbag::View> view_;
  rosbag::View::iterator it_;
  std::vector<Topic> topics_;
  std::set<std::string> skipped_;
  std::deque<Pending> pending_;
  std::vector<double> values_;
  std::vector<double> current_;
  std::uint64_t index_ = 0;
  std::uint64_t samples_ = 0;
  bool failed_ = false;
  std::string error_;
};

}  // namespace

[[nodiscard]] Expected<std::unique_ptr<InputSource>> open_bag(const std::string& bag, const std::string& mapping) {
  ros_common::MappingLoad m = ros_common::load_mapping(mapping);
  if (!m.mapping) {
    std::string all;
    for (const auto& d : m.diagnostics) all += (all.empty() ? "" : "\n") + spec::format(d);
    return fail(ErrorCode::Parse, all.empty() ? "cannot read mapping file '" + mapping + "'" : all);
  }
  auto source = std::make_unique<BagSource>(bag, std::move(*m.mapping));
  if (auto opened = source->open(); !opened) return tl::unexpected(opened.error());
  return std::unique_ptr<InputSource>(std::move(source));
}

}  // namespace safecass::replay
