#include "scene/params.h"

#include <cmath>

namespace bpm {

std::string canonical_param_type(const std::string& t) {
  if (t == "float" || t == "integer" || t == "bool" || t == "string" || t == "rgb" ||
      t == "spectrum" || t == "blackbody" || t == "point2" || t == "vector2" || t == "point3" ||
      t == "vector3" || t == "normal" || t == "texture")
    return t;
  if (t == "point") return "point3";
  if (t == "vector") return "vector3";
  if (t == "normal3") return "normal";
  if (t == "color") return "rgb";
  return "";
}

void ParamSet::add(Param p) {
  for (const Param& q : params_)
    if (q.name == p.name) throw Error(p.loc, "parameter \"" + p.name + "\" given twice");
  params_.push_back(std::move(p));
}

void ParamSet::set(Param p) {
  for (Param& q : params_)
    if (q.name == p.name) {
      q = std::move(p);
      return;
    }
  params_.push_back(std::move(p));
}

const Param* ParamSet::find_any(const std::string& name) const {
  for (const Param& p : params_)
    if (p.name == name) return &p;
  return nullptr;
}

const Param* ParamSet::find(const std::string& name, const std::string& type) const {
  const Param* p = find_any(name);
  if (!p) return nullptr;
  if (p->type != type)
    throw Error(p->loc, "parameter \"" + name + "\" has type \"" + p->type + "\"; expected \"" +
                            type + "\"");
  p->used = true;
  return p;
}

namespace {
const Param* find_one(const ParamSet& ps, const std::string& name, const std::string& type) {
  const Param* p = ps.find(name, type);
  if (p && p->count() != 1)
    throw Error(p->loc,
                "parameter \"" + name + "\" takes one value; got " + std::to_string(p->count()));
  return p;
}
void check_finite(const Param& p) {
  for (double v : p.numbers)
    if (!std::isfinite(v))
      throw Error(p.loc, "parameter \"" + p.name + "\" has a non-finite value");
}
}  // namespace

float ParamSet::get_float(const std::string& name, float def) const {
  const Param* p = find_one(*this, name, "float");
  if (!p) return def;
  check_finite(*p);
  return float(p->numbers[0]);
}

int ParamSet::get_int(const std::string& name, int def) const {
  const Param* p = find_one(*this, name, "integer");
  return p ? int(p->numbers[0]) : def;
}

bool ParamSet::get_bool(const std::string& name, bool def) const {
  const Param* p = find_one(*this, name, "bool");
  return p ? bool(p->bools[0]) : def;
}

std::string ParamSet::get_string(const std::string& name, const std::string& def) const {
  const Param* p = find_one(*this, name, "string");
  return p ? p->strings[0] : def;
}

Vec3 ParamSet::get_point3(const std::string& name, Vec3 def) const {
  auto v = get_point3s(name);
  if (v.empty()) return def;
  if (v.size() != 1) throw Error(find_any(name)->loc, "parameter \"" + name + "\" takes one point");
  return v[0];
}

std::vector<float> ParamSet::get_floats(const std::string& name) const {
  const Param* p = find(name, "float");
  if (!p) return {};
  check_finite(*p);
  return std::vector<float>(p->numbers.begin(), p->numbers.end());
}

std::vector<int> ParamSet::get_ints(const std::string& name) const {
  const Param* p = find(name, "integer");
  if (!p) return {};
  return std::vector<int>(p->numbers.begin(), p->numbers.end());
}

namespace {
std::vector<Vec3> triples(const Param* p) {
  if (!p) return {};
  check_finite(*p);
  if (p->numbers.size() % 3 != 0)
    throw Error(p->loc, "parameter \"" + p->name + "\" needs a multiple of 3 values; got " +
                            std::to_string(p->numbers.size()));
  std::vector<Vec3> out(p->numbers.size() / 3);
  for (size_t i = 0; i < out.size(); ++i)
    out[i] =
        Vec3(float(p->numbers[3 * i]), float(p->numbers[3 * i + 1]), float(p->numbers[3 * i + 2]));
  return out;
}
}  // namespace

std::vector<Vec3> ParamSet::get_point3s(const std::string& name) const {
  return triples(find(name, "point3"));
}
std::vector<Vec3> ParamSet::get_normals(const std::string& name) const {
  return triples(find(name, "normal"));
}
std::vector<Vec3> ParamSet::get_vector3s(const std::string& name) const {
  return triples(find(name, "vector3"));
}

std::vector<Vec2> ParamSet::get_point2s(const std::string& name) const {
  const Param* p = find(name, "point2");
  if (!p) return {};
  check_finite(*p);
  if (p->numbers.size() % 2 != 0)
    throw Error(p->loc, "parameter \"" + name + "\" needs an even number of values");
  std::vector<Vec2> out(p->numbers.size() / 2);
  for (size_t i = 0; i < out.size(); ++i)
    out[i] = {float(p->numbers[2 * i]), float(p->numbers[2 * i + 1])};
  return out;
}

void ParamSet::warn_unused(const std::string& what) const {
  for (const Param& p : params_)
    if (!p.used)
      warning(p.loc, "parameter \"" + p.type + " " + p.name + "\" of " + what +
                         " is not supported and was ignored");
}

void ParamSet::require(const std::string& name, bool ok, const std::string& what,
                       const FileLoc& fallback) const {
  if (ok) return;
  const Param* p = find_any(name);
  throw Error(p ? p->loc : fallback, name + " " + what);
}

}  // namespace bpm
