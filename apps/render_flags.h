// The flags of `bpm render` (docs/USAGE.md lists them), for the program and for the Python module,
// which turns its keyword arguments into the same flags: both check a request the same way and
// read it into the same RenderRequest.
#pragma once
#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "render/render_job.h"

namespace bpm {

// Adds the `render` command with its flags, which fill `request`.
CLI::App* add_render_command(CLI::App& app, RenderRequest& request);

// The request that `bpm render ARGS...` makes; throws Error with CLI11's message when an argument
// is unknown, missing or out of its range.
RenderRequest parse_render_request(const std::vector<std::string>& args);

}  // namespace bpm
