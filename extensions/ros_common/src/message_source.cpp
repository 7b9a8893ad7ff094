#include "safecass/ros_common/message_source.hpp"

namespace safecass::ros_common {

[[nodiscard]] Expected<Mapping> load_log_mapping(const std::string& path) {
  MappingLoad m = load_mapping(path);
  if (m.mapping) return std::move(*m.mapping);
  const std::string all = spec::to_text(m.diagnostics);
  return fail(ErrorCode::Parse, all.empty() ? "cannot read mapping file '" + path + "'" : all);
}

Expected<void> MessageSource::bind(Monitor& monitor) {
  std::vector<std::string> names;
  for (const TopicMapping& t : mapping_.topics) {
    Topic topic{t, {}};
    for (const FieldBinding& b : t.signals) {
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
      names.push_back(t.topic);
      topics_.push_back(std::move(topic));
    }
  }
  if (topics_.empty())
    return fail(ErrorCode::Parse, mapping_.path + ": no topic of the mapping feeds a signal of the system");
  return select(names);
}

const MessageSource::Topic* MessageSource::topic(std::string_view name) const {
  for (const Topic& t : topics_) {
    if (t.mapping.topic == name) return &t;
  }
  return nullptr;
}

bool MessageSource::feed(const Topic& t, const MessageNumbers& numbers, Time time) {
  // All of a message's samples or none: a message that fails half-way pushes nothing.
  const std::size_t values_before = values_.size(), pending_before = pending_.size();
  for (const Binding& b : t.bindings) {
    const std::size_t at = values_.size();
    values_.resize(at + b.width);
    std::string why;
    if (!extract(b.path, numbers, values_.data() + at, b.width, why)) {
      values_.resize(values_before);
      pending_.resize(pending_before);
      return fail_message(t.mapping.topic, why);
    }
    pending_.push_back(Pending{time, b.signal, at});
  }
  return true;
}

bool MessageSource::fail_message(const std::string& topic, const std::string& reason) {
  return fail_log("(" + topic + "): " + reason);
}

bool MessageSource::fail_log(const std::string& reason) {
  failed_ = true;
  error_ = path_ + ": message " + std::to_string(index_) + (reason.front() == '(' ? " " : ": ") + reason;
  return false;
}

InputItem MessageSource::next() {
  InputItem item;
  while (pending_.empty()) {
    if (failed_) {
      item.kind = InputItem::Kind::Error;
      return item;
    }
    const Read r = read();
    if (r == Read::End) {
      item.kind = InputItem::Kind::End;
      return item;
    }
    if (r == Read::Error) failed_ = true;
  }
  const Pending& p = pending_.front();
  current_.assign(values_.begin() + static_cast<std::ptrdiff_t>(p.offset),
                  values_.begin() + static_cast<std::ptrdiff_t>(p.offset + p.signal->size()));
  item.kind = InputItem::Kind::Sample;
  item.time = p.time;
  item.signal = p.signal;
  item.values = current_.data();
  pending_.pop_front();
  if (pending_.empty()) values_.clear();
  ++samples_;
  return item;
}

std::vector<std::string> MessageSource::notes() const {
  std::vector<std::string> out;
  for (const std::string& s : skipped_)
    out.push_back(path_ + ": mapped signal " + s + " is not in the system: not fed");
  return out;
}

}  // namespace safecass::ros_common
