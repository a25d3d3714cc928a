#pragma once
/// \file
/// ControllerHost: the non-RT command side of a Controller. Turns Logix ST
/// instruction calls into planner Requests (motion/st_parser.hpp), creating
/// control tags on first use, queues them for the RT thread, and reads and
/// writes tags through the status snapshot. Motion scripts run against it
/// (it is their ScriptHost) and so does the canmotionctl socket server.
///
/// Not realtime. Not thread-safe: one thread uses one host.

#include <optional>
#include <string>
#include <string_view>

#include "rt/controller/controller.hpp"
#include "rt/controller/script.hpp"
#include "rt/controller/tags.hpp"

namespace canmotion::rt {

class ControllerHost final : public script::ScriptHost {
 public:
  explicit ControllerHost(Controller& c) : c_(c), tags_(c) {}

  std::optional<std::string> check_call(std::string_view call) override;
  std::optional<std::string> check_tag(std::string_view tag, bool for_write) override;
  std::optional<std::string> execute(std::string_view call, std::string* control_tag) override;
  bool settled() override;
  std::optional<double> read(std::string_view tag, std::string* error) override;
  std::optional<std::string> write(std::string_view tag, double value) override;
  /// Switch the controller to Run or Program (a command to the RT thread;
  /// settled() waits for it). An error when the command queue is full.
  std::optional<std::string> set_mode(motion::ControllerMode m);
  void declare(std::string_view tag) override;

  /// Sequence number of the last command queued (0 = none).
  [[nodiscard]] std::uint64_t last_seq() const noexcept { return last_seq_; }
  /// The newest status (refreshed by read/settled; call refresh() to force).
  const Status& refresh();
  TagTable& tags() noexcept { return tags_; }
  Controller& controller() noexcept { return c_; }

 private:
  /// Parse and bind; creates control tags named in the call.
  std::optional<std::string> bind(std::string_view call, motion::Request& out, std::string* control_tag);
  Controller& c_;
  TagTable tags_;
  std::unique_ptr<Status> status_ = std::make_unique<Status>();  // large: keep it off the stack
  std::uint64_t last_seq_ = 0;
};

}  // namespace canmotion::rt
