// Pixel reconstruction filters as pbrt-v4 defines them, used the way pbrt-v4 uses them: each
// camera sample's offset from the pixel centre is drawn from the filter, and the sample is weighted
// by f / pdf (1 for filters that are never negative), so each sample lands in one pixel only.
#pragma once
#include <string>
#include <vector>

#include "base/sampling.h"
#include "base/vec.h"

namespace bpm {

enum class FilterType { kBox, kTriangle, kGaussian, kMitchell, kLanczos };

struct FilterSettings {
  FilterType type = FilterType::kGaussian;
  Vec2 radius{1.5f, 1.5f};
  float sigma = 0.5f;                // gaussian
  float b = 1.0f / 3, c = 1.0f / 3;  // mitchell
  float tau = 3;                     // lanczos
};

struct FilterSample {
  Vec2 offset;  // from the pixel centre, in pixels
  float weight;
};

class Filter {
 public:
  explicit Filter(const FilterSettings& s);
  float evaluate(Vec2 p) const;
  FilterSample sample(Vec2 u) const;
  // The density over offsets (per square pixel) that sample() draws from: f / integral(f) for
  // the box and the triangle, the tabulated |f| / its integral for the others.
  float sample_density(Vec2 offset) const;
  // What one sample's weight averages with, per square pixel: f / integral(f) (the tabulated f
  // for the filters sampled from their table), so that a value spread by it over the offsets
  // adds to a pixel what camera samples weighted by sample() add in expectation.
  float normalized(Vec2 offset) const;
  // What sample()'s weights average: 1 for the box and the triangle, the tabulated f's integral
  // for the others.
  float mean_weight() const { return values_.empty() ? 1.0f : integral_; }
  const FilterSettings& settings() const { return s_; }
  std::string name() const;

 private:
  int cell_of(Vec2 offset) const;  // the tabulated cell holding offset (inside the radius)
  FilterSettings s_;
  // Tabulated |f| for filters without an analytic sampler.
  int nx_ = 0, ny_ = 0;
  std::vector<float> values_;
  Distribution1D cells_;
  float integral_ = 0;
};

}  // namespace bpm
