// Photon emission guided toward what the camera sees. A photon's emission is drawn from five
// uniform numbers: the light, u_pos (the point on it) and u_dir (the direction). The guide cuts
// that primary sample space into cells (per light, a grid over u_pos times a grid over u_dir),
// learns from earlier iterations how much a photon started in each cell adds to the image,
// relative to the pixels it reaches, and draws cells from an even mixture of that and the
// unguided density (lights in proportion to power, u_pos and u_dir uniform). Inside a cell the
// numbers stay uniform, so the density ratio is constant per cell: a photon's flux is multiplied
// by unguided / guided probability of its cell, which is at most 2. Every iteration is therefore
// an unbiased estimate of its radius-blurred image, whatever was learnt.
#pragma once
#include <cstdint>
#include <vector>

#include "base/bytes.h"
#include "base/rng.h"
#include "base/sampling.h"
#include "scene/render_scene.h"

namespace bpm {

// Where a photon starts, in primary sample space, and how its flux is weighted.
struct EmissionDraw {
  int light = 0;
  float light_pmf = 0;  // the unguided probability of the light (power)
  Vec2 u_pos, u_dir;
  uint32_t cell = 0;
  float weight = 1;  // unguided / guided probability of the cell
};

// What one photon added: its cell and the sum of its relative contributions, each computed as if
// it had been emitted without guidance (weight removed).
struct CellScore {
  uint32_t cell;
  float score;
};

class EmissionGuide {
 public:
  EmissionGuide() = default;
  explicit EmissionGuide(const RenderScene& scene);
  bool empty() const { return cells_ == 0; }
  size_t cells() const { return cells_; }
  // Draws the emission of one photon (six numbers from rng: two choose the cell).
  EmissionDraw sample(Rng& rng) const;
  // Starts fetching the part of the table that sample(rng) will read (rng itself is not advanced):
  // the table is read at random, once per photon, and may not fit in the cache.
  void prefetch(Rng rng) const {
    if (!bins_.empty()) __builtin_prefetch(&bins_[size_t(bin_of(rng.next_u32()))]);
  }
  // Adds the scores of photons, in a fixed order (the sums must not depend on the thread count),
  // to what was learnt since the last merge; sampling does not change until then.
  void learn(const std::vector<CellScore>& scores);
  // Appends what was learnt since the last merge (2 cells() sums that add across processes) and
  // starts again from nothing.
  void take_learnt(std::vector<double>* out);
  // Adds learnt sums (take_learnt's, of one process or summed over several) and rebuilds the
  // guided density from everything merged so far; until a photon has scored, the density stays
  // the unguided one.
  void merge(const double* learnt);
  // Sets what was learnt since the last merge to take_learnt's layout of sums (taken back).
  void keep_learnt(const double* learnt);
  // take_learnt and merge of this guide alone.
  void update();
  // The share of photons guidance moves (total variation between the guided and unguided
  // densities): 0 before anything is learnt, at most 1/2 with the even mixture.
  double moved() const { return moved_; }
  // What it has merged and what it learnt since, for a checkpoint; load() takes them back into a
  // guide of the same scene and rebuilds the density as merge() had.
  void save(ByteWriter& w) const;
  void load(ByteReader& r);

 private:
  struct LightCells {
    uint32_t first;          // index of the light's first cell
    int pos_res, dir_res;    // powers of two
    int pos_bits, dir_bits;  // their base-2 logarithms: cells are found by shifts, not divisions
  };
  std::vector<LightCells> lights_;
  std::vector<float> unguided_;  // probability of each cell without guidance
  // The guided density's alias table, with everything a draw reads in its bin, the alias's part
  // included: one cache line per photon (the table holds up to a million cells).
  struct alignas(32) Bin {
    float keep;         // probability of keeping the bin's own cell
    uint32_t alias;     // the cell drawn otherwise
    float pmf[2];       // guided probability of the own cell [0] and of the alias [1]
    float unguided[2];  // their unguided probabilities
  };
  std::vector<Bin> bins_;
  uint32_t bin_of(uint32_t bits) const { return uint32_t((uint64_t(bits) * bins_.size()) >> 32); }
  void set_density(const std::vector<float>& guided);
  void rebuild();
  std::vector<double> score_sum_, photons_;      // merged
  std::vector<double> new_score_, new_photons_;  // learnt since the last merge
  size_t cells_ = 0;
  double moved_ = 0;
};

}  // namespace bpm
