// The memory budget of a render (--memory): how much the machine has, sizes as a user writes them,
// and the error a render gives when what it needs would not fit. A render checks what it is about
// to allocate against the budget before allocating it; it never relies on the kernel's OOM killer.
#pragma once
#include <cstdint>
#include <string>

namespace bpm {

// The memory this process may use: the machine's physical memory, or the control group's limit
// when that is lower (a container).
uint64_t machine_memory_bytes();

// The budget when --memory is not given: three quarters of machine_memory_bytes(), leaving room
// for the scene, the libraries and the rest of the machine.
uint64_t default_memory_budget();

// "512M", "8G", "1.5GiB", "4096" (MiB without a unit), "100K": bytes. Throws Error on anything
// else, or on a size under 1 MiB.
uint64_t parse_memory_size(const std::string& text);

// "1.50 GiB", "12.3 MiB", "800 KiB".
std::string format_bytes(double bytes);

// Throws Error("<what> needs <needed>, more than the memory budget of <budget> ...; <advice>")
// when needed > budget (a budget of 0 is no budget).
void check_memory(const std::string& what, double needed, uint64_t budget,
                  const std::string& advice);

}  // namespace bpm
