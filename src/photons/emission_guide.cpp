#include "photons/emission_guide.h"

#include <algorithm>
#include <bit>
#include <cmath>

namespace bpm {
namespace {

// Cells per light: a point, spot, goniometric or projection light has one position, a distant
// light one direction; the grid shrinks when a scene has many lights (emissive meshes), so that
// the guide stays within about a million cells.
constexpr size_t kMaxCells = size_t(1) << 20;

bool has_one_position(const Light& l) {
  return std::holds_alternative<PointLight>(l) || std::holds_alternative<SpotLight>(l) ||
         std::holds_alternative<GoniometricLight>(l) || std::holds_alternative<ProjectionLight>(l);
}

}  // namespace

EmissionGuide::EmissionGuide(const RenderScene& scene) {
  const size_t n = scene.lights.size();
  if (n == 0 || scene.light_distribution.empty()) return;
  // Resolutions (position, direction) from the finest that fits.
  for (auto [pos, dir] : {std::pair{4, 16}, std::pair{2, 8}, std::pair{1, 4}, std::pair{1, 1}}) {
    lights_.clear();
    size_t total = 0;
    for (const Light& l : scene.lights) {
      int p = has_one_position(l) ? 1 : pos;
      int d = std::holds_alternative<DistantLight>(l) ? 1 : (has_one_position(l) ? 2 * dir : dir);
      lights_.push_back(
          {uint32_t(total), p, d, std::countr_zero(unsigned(p)), std::countr_zero(unsigned(d))});
      total += size_t(p * p) * size_t(d * d);
    }
    cells_ = total;
    if (total <= kMaxCells) break;
  }
  unguided_.resize(cells_);
  for (size_t li = 0; li < n; ++li) {
    const LightCells& lc = lights_[li];
    size_t count = size_t(lc.pos_res * lc.pos_res) * size_t(lc.dir_res * lc.dir_res);
    float p = scene.light_distribution.pmf(int(li)) / float(count);
    std::fill_n(unguided_.begin() + lc.first, count, p);
  }
  set_density(unguided_);
  score_sum_.assign(cells_, 0.0);
  photons_.assign(cells_, 0.0);
  new_score_.assign(cells_, 0.0);
  new_photons_.assign(cells_, 0.0);
}

EmissionDraw EmissionGuide::sample(Rng& rng) const {
  EmissionDraw d;
  const uint32_t bits = rng.next_u32();
  const uint32_t own = bin_of(bits);
  const Bin& b = bins_[own];
  const int k = rng.uniform() < b.keep ? 0 : 1;  // as AliasTable::sample
  const uint32_t cell = k == 0 ? own : b.alias;
  const float pmf = b.pmf[k];
  // The light owning the cell: the last whose first cell is not after it.
  auto it = std::upper_bound(lights_.begin(), lights_.end(), cell,
                             [](uint32_t c, const LightCells& l) { return c < l.first; });
  const int li = int(it - lights_.begin()) - 1;
  const LightCells& lc = lights_[size_t(li)];
  uint32_t local = cell - lc.first;
  const uint32_t dir_cells = uint32_t(lc.dir_res * lc.dir_res);
  const uint32_t pos_cell = local >> (2 * lc.dir_bits), dir_cell = local & (dir_cells - 1);
  auto in_cell = [&](uint32_t index, int res, int bits) {
    float x = (float(index & uint32_t(res - 1)) + rng.uniform()) / float(res);
    float y = (float(index >> bits) + rng.uniform()) / float(res);
    return Vec2{std::min(x, 0x1.fffffep-1f), std::min(y, 0x1.fffffep-1f)};
  };
  d.light = li;
  d.u_pos = in_cell(pos_cell, lc.pos_res, lc.pos_bits);
  d.u_dir = in_cell(dir_cell, lc.dir_res, lc.dir_bits);
  d.cell = cell;
  const float unguided = b.unguided[k];
  d.light_pmf = unguided * float(lc.pos_res * lc.pos_res) * float(dir_cells);
  d.weight = pmf > 0 ? unguided / pmf : 0;
  return d;
}

void EmissionGuide::learn(const std::vector<CellScore>& scores) {
  for (const CellScore& s : scores) {
    // A non-finite score (a numerical accident) would poison its cell's sum for good.
    if (std::isfinite(s.score) && s.score >= 0) new_score_[s.cell] += s.score;
    new_photons_[s.cell] += 1;
  }
}

void EmissionGuide::take_learnt(std::vector<double>* out) {
  out->insert(out->end(), new_score_.begin(), new_score_.end());
  out->insert(out->end(), new_photons_.begin(), new_photons_.end());
  std::fill(new_score_.begin(), new_score_.end(), 0.0);
  std::fill(new_photons_.begin(), new_photons_.end(), 0.0);
}

void EmissionGuide::keep_learnt(const double* learnt) {
  new_score_.assign(learnt, learnt + cells_);
  new_photons_.assign(learnt + cells_, learnt + 2 * cells_);
}

void EmissionGuide::merge(const double* learnt) {
  for (size_t c = 0; c < cells_; ++c) {
    score_sum_[c] += learnt[c];
    photons_[c] += learnt[cells_ + c];
  }
  rebuild();
}

void EmissionGuide::update() {
  std::vector<double> learnt;
  take_learnt(&learnt);
  merge(learnt.data());
}

void EmissionGuide::rebuild() {
  if (cells_ == 0) return;
  // Learnt density: the unguided probability of a cell times the mean score of its photons.
  std::vector<double> learnt(cells_, 0.0);
  double total = 0;
  for (size_t c = 0; c < cells_; ++c) {
    if (photons_[c] > 0) learnt[c] = double(unguided_[c]) * score_sum_[c] / photons_[c];
    total += learnt[c];
  }
  if (!(total > 0) || !std::isfinite(total)) return;
  std::vector<float> mixed(cells_);
  moved_ = 0;
  for (size_t c = 0; c < cells_; ++c) {
    double g = 0.5 * double(unguided_[c]) + 0.5 * learnt[c] / total;
    mixed[c] = float(g);
    moved_ += 0.5 * std::fabs(g - double(unguided_[c]));
  }
  set_density(mixed);
}

void EmissionGuide::set_density(const std::vector<float>& guided) {
  const AliasTable table(guided);
  bins_.resize(cells_);
  for (size_t c = 0; c < cells_; ++c) {
    const int i = int(c);
    const uint32_t a = table.alias(i);
    bins_[c] = {table.keep(i), a, {table.pmf(i), table.pmf(int(a))}, {unguided_[c], unguided_[a]}};
  }
}

void EmissionGuide::save(ByteWriter& w) const {
  for (const std::vector<double>* v : {&score_sum_, &photons_, &new_score_, &new_photons_})
    w.put_vector(*v);
}

void EmissionGuide::load(ByteReader& r) {
  for (std::vector<double>* v : {&score_sum_, &photons_, &new_score_, &new_photons_}) {
    *v = r.get_vector<double>();
    if (v->size() != cells_)
      throw Error(r.what() + " was learnt on another scene's lights (emission guide cells)");
  }
  rebuild();
}

}  // namespace bpm
