// A ROS 1 bag as a replay source. C++17: Debian's ROS message headers do not compile as C++20.

#include "safecass/ros1/bag_source.hpp"

#include <rosbag/bag.h>
#include <rosbag/view.h>

#include <deque>
#include <set>

#include "safecass/ros1/messages.hpp"
#include "safecass/ros_common/mapping.hpp"
#include "safecass/ros_common/message_source.hpp"

namespace safecass::ros1 {

namespace {

class BagSource final : public ros_common::MessageSource {
public:
  using MessageSource::MessageSource;

  [[nodiscard]] Expected<void> open() {
    try {
      bag_.open(path(), rosbag::bagmode::Read);
      rosbag::View all(bag_);
      begin_ = all.getBeginTime();
    } catch (const std::exception& e) {
      return fail(ErrorCode::Parse, path() + ": not a readable ROS bag (truncated or damaged?): " + e.what());
    }
    return {};
  }

private:
  [[nodiscard]] Expected<void> select(const std::vector<std::string>& topics) override {
    try {
      view_ = std::make_unique<rosbag::View>(bag_, rosbag::TopicQuery(topics));
      it_ = view_->begin();
    } catch (const std::exception& e) {
      return fail(ErrorCode::Parse, path() + ": cannot read the bag: " + e.what());
    }
    return {};
  }

  Read read() override {
    try {
      if (it_ == view_->end()) return Read::End;
      ++index_;
      const rosbag::MessageInstance& m = *it_;
      const bool ok = read_message(m);
      ++it_;
      return ok ? Read::Message : Read::Error;
    } catch (const std::exception& e) {
      fail_log("the bag is truncated or damaged (rosbag: " + std::string(e.what()) + ")");
      return Read::Error;
    }
  }

  bool read_message(const rosbag::MessageInstance& m) {
    const Topic* t = topic(m.getTopic());
    if (t == nullptr) return true;
    const ros::Duration since = m.getTime() - begin_;
    const Time time{since.toNSec()};
    const std::string expected(ros_common::to_string(t->mapping.type));
    if (m.getDataType() != expected) {
      return fail_message(t->mapping.topic, "a " + m.getDataType() + " message; the mapping says " + expected);
    }
    try {
      switch (t->mapping.type) {
        case ros_common::MessageType::Float64:
          return feed(*t, ros1::numbers_of(*m.instantiate<std_msgs::Float64>()), time);
        case ros_common::MessageType::WrenchStamped:
          return feed(*t, ros1::numbers_of(*m.instantiate<geometry_msgs::WrenchStamped>()), time);
        case ros_common::MessageType::JointState:
          return feed(*t, ros1::numbers_of(*m.instantiate<sensor_msgs::JointState>()), time);
      }
    } catch (const std::exception& e) {
      return fail_message(t->mapping.topic, "cannot be read as " + expected + " (rosbag: " + e.what() + ")");
    }
    return true;
  }

  rosbag::Bag bag_;
  ros::Time begin_;
  std::unique_ptr<rosbag::View> view_;
  rosbag::View::iterator it_;
};

}  // namespace

[[nodiscard]] Expected<std::unique_ptr<InputSource>> open_bag(const std::string& bag, const std::string& mapping) {
  auto m = ros_common::load_log_mapping(mapping);
  if (!m) return tl::unexpected(m.error());
  auto source = std::make_unique<BagSource>(bag, std::move(*m));
  if (auto opened = source->open(); !opened) return tl::unexpected(opened.error());
  return std::unique_ptr<InputSource>(std::move(source));
}

}  // namespace safecass::ros1
