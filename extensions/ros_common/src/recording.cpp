#include "safecass/ros_common/recording.hpp"

#include <cstdio>

namespace safecass::ros_common {

Expected<std::unique_ptr<NodeRecording>> NodeRecording::open(Shadow& shadow, const std::string& history_path,
                                                             FileLimits limits) {
  std::unique_ptr<NodeRecording> r(new NodeRecording());
  auto h = Recorder::open(shadow.coordinator(), history_path, 65536, limits);
  if (!h) return tl::unexpected(h.error());
  r->history_ = std::move(*h);
  InputRecorderOptions o;
  o.limits = limits;
  o.clock = "steady";
  for (const auto& c : shadow.system().components) {
    for (const auto& sig : c.signals) o.signals.push_back(sig.name);
  }
  auto in = InputRecorder::open(shadow.monitor(), InputRecorder::path_for_history(history_path), o);
  if (!in) return tl::unexpected(in.error());
  r->inputs_ = std::move(*in);
  r->inputs_->start_polling();
  return r;
}

std::vector<std::string> NodeRecording::close() {
  std::vector<std::string> losses;
  inputs_->close();
  for (std::string& loss : describe_losses(inputs_->status())) losses.push_back(std::move(loss));
  if (!inputs_->status().complete() && losses.empty()) losses.emplace_back("the input recording is incomplete");
  history_->close();
  for (std::string& loss : describe_losses(history_->status())) losses.push_back(std::move(loss));
  if (!history_->status().complete() && losses.empty()) losses.emplace_back("the history recording is incomplete");
  return losses;
}

int NodeRecording::finish(std::unique_ptr<NodeRecording>& recording) {
  if (!recording) return 0;
  int code = 0;
  for (const std::string& loss : recording->close()) {
    std::fprintf(stderr, "%s\n", loss.c_str());
    code = 2;
  }
  recording.reset();
  return code;
}

}  // namespace safecass::ros_common
