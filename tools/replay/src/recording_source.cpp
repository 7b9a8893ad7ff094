// A SAFECASS input recording as a replay source.

#include <set>

#include "safecass/replay/source.hpp"

namespace safecass::replay {

namespace {

class RecordingSource final : public InputSource {
public:
  explicit RecordingSource(std::unique_ptr<InputLogReader> reader) : reader_(std::move(reader)) {}

  [[nodiscard]] Expected<void> bind(Monitor& monitor) override {
    monitor_ = &monitor;
    return {};
  }

  InputItem next() override {
    InputItem item;
    for (;;) {
      switch (reader_->next()) {
        case InputLogReader::Item::Sample: {
          const std::uint16_t id = reader_->signal();
          if (id >= bound_.size() && !bind_up_to(id)) return error_item();
          ++samples_;
          item.kind = InputItem::Kind::Sample;
          item.time = reader_->time();
          item.signal = bound_[id];
          item.values = reader_->values();
          return item;
        }
        case InputLogReader::Item::Action:
          item.kind = InputItem::Kind::Action;
          item.time = reader_->mark_time();
          item.action = &reader_->action();
          return item;
        case InputLogReader::Item::Loss: lost_ += reader_->lost(); continue;
        case InputLogReader::Item::End: end_ = reader_->mark_time(); continue;
        case InputLogReader::Item::Eof: item.kind = InputItem::Kind::End; return item;
        case InputLogReader::Item::Error: error_ = reader_->error(); return error_item();
      }
    }
  }

  const std::string& error() const override { return error_; }
  std::optional<Time> period() const override {
    return reader_->header().period.count() > 0 ? std::optional<Time>(reader_->header().period) : std::nullopt;
  }
  std::optional<Time> start() const override { return reader_->header().start; }
  std::optional<Time> end() const override { return end_; }
  std::uint64_t samples() const override { return samples_; }
  std::string where() const override { return reader_->path() + ": record " + std::to_string(reader_->record_index()); }
  std::vector<std::string> notes() const override {
    std::vector<std::string> out;
    if (reader_->truncated()) {
      out.push_back(reader_->path() +
                    ": the recording ends inside a record (its recorder was stopped by force): replayed up to its last "
                    "whole record");
    } else if (!end_) {
      out.push_back(reader_->path() + ": the recording has no end record (its recorder did not close it)");
    }
    if (lost_ != 0) {
      out.push_back(reader_->path() + ": the recorder lost " + std::to_string(lost_) +
                    " samples of this run (marked in the recording): the replay cannot feed them");
    }
    return out;
  }

private:
  InputItem error_item() {
    InputItem item;
    item.kind = InputItem::Kind::Error;
    return item;
  }
  bool bind_up_to(std::uint16_t id) {
    while (bound_.size() <= id) {
      const auto k = static_cast<std::uint16_t>(bound_.size());
      const std::string& name = reader_->signal_name(k);
      auto s = find_input_signal(*monitor_, name);
      if (!s) {
        error_ = reader_->path() + ": record " + std::to_string(reader_->record_index()) + ": " + s.error().message;
        return false;
      }
      if ((*s)->size() != reader_->signal_width(k)) {
        error_ = reader_->path() + ": record " + std::to_string(reader_->record_index()) + ": signal '" + name +
                 "' has " + std::to_string(reader_->signal_width(k)) + " values in the recording and size " +
                 std::to_string((*s)->size()) + " in the system";
        return false;
      }
      bound_.push_back(*s);
    }
    return true;
  }

  std::unique_ptr<InputLogReader> reader_;
  Monitor* monitor_ = nullptr;
  std::vector<Signal*> bound_;
  std::string error_;
  std::optional<Time> end_;
  std::uint64_t lost_ = 0;
  std::uint64_t samples_ = 0;
};

}  // namespace

std::unique_ptr<InputSource> open_recording(std::unique_ptr<InputLogReader> reader) {
  return std::make_unique<RecordingSource>(std::move(reader));
}

}  // namespace safecass::replay
