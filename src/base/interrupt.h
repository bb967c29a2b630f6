// Ctrl-C and SIGTERM: the handlers only raise a flag; the render loops look at it between tiles,
// blocks, photon batches and passes, stop, and the image so far is still written. A closed
// stderr (SIGPIPE) is ignored, so that it cannot end a render either.
#pragma once
#include <atomic>

namespace bpm {

std::atomic<bool>& interrupt_flag();
void install_interrupt_handlers();
inline bool interrupted() { return interrupt_flag().load(std::memory_order_relaxed); }

}  // namespace bpm
