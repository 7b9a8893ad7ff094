#pragma once
/// @file message_source.hpp
/// What the input sources of ROS logs share (a ROS 1 bag, in the ROS 1 extension; a ROS 2 bag, in
/// `safecass replay`): the mapping file binds topics to the replayed system's input signals with
/// the live bridges' field paths, and each message's numbers become samples, in order. A subclass
/// reads its log format and calls feed() for each message of a bound topic. C++17 (the ROS 1 bag
/// source includes ROS headers).

#include <cstdint>
#include <deque>
#include <memory>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "safecass/record/input_source.hpp"
#include "safecass/ros_common/fields.hpp"
#include "safecass/ros_common/mapping.hpp"

namespace safecass::ros_common {

/// The mapping file of `path`, or every problem in it. Errors: Parse.
[[nodiscard]] Expected<Mapping> load_log_mapping(const std::string& path);

class MessageSource : public InputSource {
public:
  MessageSource(std::string path, Mapping mapping) : path_(std::move(path)), mapping_(std::move(mapping)) {}

  [[nodiscard]] Expected<void> bind(Monitor& monitor) final;
  InputItem next() final;
  const std::string& error() const final { return error_; }
  std::uint64_t samples() const final { return samples_; }
  std::string where() const final { return path_ + ": message " + std::to_string(index_); }
  std::vector<std::string> notes() const final;

protected:
  struct Binding {
    Signal* signal;
    FieldPath path;
    std::size_t width;
  };
  struct Topic {
    TopicMapping mapping;
    std::vector<Binding> bindings;
  };
  enum class Read : std::uint8_t { Message, End, Error };

  /// After bind(): read only these topics (ROS names). Errors: Parse, with the reason.
  [[nodiscard]] virtual Expected<void> select(const std::vector<std::string>& topics) = 0;
  /// Reads one message (counting it in index_) and calls feed() when it is of a bound topic.
  /// Error: after fail_log() or fail_message().
  virtual Read read() = 0;

  /// The bound topic named `name`, or null.
  const Topic* topic(std::string_view name) const;
  /// A message of `t` at `time` (since the log's first message): its samples, in binding order.
  bool feed(const Topic& t, const MessageNumbers& numbers, Time time);
  /// "file: message N (topic): reason".
  bool fail_message(const std::string& topic, const std::string& reason);
  /// "file: message N: reason".
  bool fail_log(const std::string& reason);

  const std::string& path() const { return path_; }
  const Mapping& mapping() const { return mapping_; }
  std::uint64_t index_ = 0;  ///< messages read, the current one included

private:
  struct Pending {
    Time time;
    Signal* signal;
    std::size_t offset;
  };
  std::string path_;
  Mapping mapping_;
  std::vector<Topic> topics_;
  std::set<std::string> skipped_;
  std::deque<Pending> pending_;
  std::vector<double> values_;
  std::vector<double> current_;
  std::uint64_t samples_ = 0;
  bool failed_ = false;
  std::string error_;
};

/// A `Source` (a MessageSource with `Expected<void> open()`) of the log at `log`, with the mapping
/// file at `mapping`. Errors: the mapping's (Parse), then open()'s.
template <class Source>
[[nodiscard]] Expected<std::unique_ptr<InputSource>> open_message_source(const std::string& log,
                                                                         const std::string& mapping) {
  auto m = load_log_mapping(mapping);
  if (!m) return tl::unexpected(m.error());
  auto source = std::make_unique<Source>(log, std::move(*m));
  if (auto opened = source->open(); !opened) return tl::unexpected(opened.error());
  return std::unique_ptr<InputSource>(std::move(source));
}

}  // namespace safecass::ros_common
