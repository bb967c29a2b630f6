#include "base/interrupt.h"

#include <csignal>

namespace bpm {

std::atomic<bool>& interrupt_flag() {
  static std::atomic<bool> flag{false};
  return flag;
}

namespace {
void on_signal(int) { interrupt_flag().store(true); }
}  // namespace

void install_interrupt_handlers() {
  std::signal(SIGINT, on_signal);
  std::signal(SIGTERM, on_signal);
  // A reader of the progress that goes away (stderr piped into head) must not kill the render:
  // writes to it fail quietly and the outputs are still written.
  std::signal(SIGPIPE, SIG_IGN);
}

}  // namespace bpm
