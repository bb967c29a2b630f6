// Typed parameter lists of pbrt-v4 directives ("float radius" [ 1 ]). Getters check the type and
// the number of values, and mark a parameter used so that unused ones can be reported.
#pragma once
#include <string>
#include <vector>

#include "base/error.h"
#include "base/vec.h"

namespace bpm {

struct Param {
  std::string type;  // canonical: float integer bool string rgb spectrum blackbody point2 vector2
                     // point3 vector3 normal texture
  std::string name;
  FileLoc loc;
  std::vector<double> numbers;
  std::vector<std::string> strings;
  std::vector<bool> bools;
  mutable bool used = false;
  size_t count() const { return numbers.size() + strings.size() + bools.size(); }
};

class ParamSet {
 public:
  void add(Param p);
  // Replaces the parameter of p's name (whatever its type), or adds p.
  void set(Param p);
  bool empty() const { return params_.empty(); }
  const std::vector<Param>& all() const { return params_; }

  // nullptr when absent. Throws when present with another type.
  const Param* find(const std::string& name, const std::string& type) const;
  // Any parameter called name, whatever its type.
  const Param* find_any(const std::string& name) const;

  float get_float(const std::string& name, float def) const;
  int get_int(const std::string& name, int def) const;
  bool get_bool(const std::string& name, bool def) const;
  std::string get_string(const std::string& name, const std::string& def) const;
  Vec3 get_point3(const std::string& name, Vec3 def) const;
  std::vector<float> get_floats(const std::string& name) const;
  std::vector<int> get_ints(const std::string& name) const;
  std::vector<Vec3> get_point3s(const std::string& name) const;   // point3
  std::vector<Vec3> get_normals(const std::string& name) const;   // normal
  std::vector<Vec3> get_vector3s(const std::string& name) const;  // vector3
  std::vector<Vec2> get_point2s(const std::string& name) const;   // point2

  // Throws "NAME WHAT" at the parameter's place (or at `fallback` when it is absent) unless ok.
  void require(const std::string& name, bool ok, const std::string& what,
               const FileLoc& fallback) const;

  // Warns, naming file:line, for each parameter no getter asked for.
  void warn_unused(const std::string& what) const;

 private:
  std::vector<Param> params_;
};

// Canonical type name of a pbrt-v4 parameter type ("point" -> "point3", "color" -> "rgb"), or ""
// when the type is unknown.
std::string canonical_param_type(const std::string& type);

}  // namespace bpm
