// Checkpoint files: what a render needs to go on after it was interrupted or killed (`bpm render
// ... --resume OUT.checkpoint`), and to end with the image an uninterrupted render of the same
// length makes. A checkpoint holds
//   - the render's identity: what must be the same for the resumed passes to continue the same
//     estimate (the scene files' contents, resolution, integrator and its settings, seed, depth,
//     filter, adaptive sampling, M-images); budgets (passes, time, accuracy) and threads may
//     differ;
//   - the film's sums (Film::save), and the render state (RenderState: passes done, sampling
//     probabilities, what bpm's guide learnt).
// Layout: "BPMCKPT\n", a format version, the identity as JSON text, the film, the state, then an
// FNV-1a checksum of all that. Values are in the machine's own layout (a checkpoint moves between
// machines of the same architecture).
#pragma once
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "film/film.h"
#include "integrator/options.h"
#include "render/renderer.h"

namespace bpm {

struct Checkpoint {
  nlohmann::json identity;
  std::vector<uint8_t> film;  // Film::save
  RenderState state;
};

// The identity of a render of `ls` with `opt` (scene_files: ParsedScene::files, whose contents are
// fingerprinted with those of ls.data_files, the meshes, images and spectra the scene read;
// m_images: the film's).
nlohmann::json render_identity(const std::vector<std::string>& scene_files, const LoadedScene& ls,
                               const RenderOptions& opt, int m_images);

// The file's bytes for a render with this identity, film and state.
std::vector<uint8_t> encode_checkpoint(const nlohmann::json& identity, const Film& film,
                                       const RenderState& state);
// Throws Error naming the file when it is not a checkpoint, is of another format version, or is
// truncated or corrupt.
Checkpoint read_checkpoint(const std::string& path);
// Throws Error naming every part of the identity that differs between the checkpoint at `path`
// and this render.
void check_identity(const nlohmann::json& saved, const nlohmann::json& current,
                    const std::string& path);

}  // namespace bpm
