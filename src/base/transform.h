// Affine transforms as 4x4 matrices (row-major, column vectors) with their inverse kept beside.
#pragma once
#include <array>
#include <optional>

#include "base/vec.h"

namespace bpm {

using Matrix4 = std::array<std::array<double, 4>, 4>;

Matrix4 matrix_identity();
Matrix4 matrix_multiply(const Matrix4& a, const Matrix4& b);
Matrix4 matrix_transpose(const Matrix4& m);
std::optional<Matrix4> matrix_inverse(const Matrix4& m);

class Transform {
 public:
  Transform() : m_(matrix_identity()), inv_(matrix_identity()) {}
  Transform(const Matrix4& m, const Matrix4& inv) : m_(m), inv_(inv) {}
  // Returns nullopt when m is singular.
  static std::optional<Transform> from_matrix(const Matrix4& m);
  static Transform translate(Vec3 d);
  static Transform scale(Vec3 s);
  static Transform rotate(float angle_degrees, Vec3 axis);
  // Camera-from-world of a camera at eye looking at look (pbrt's LookAt).
  static std::optional<Transform> look_at(Vec3 eye, Vec3 look, Vec3 up);

  Transform operator*(const Transform& o) const;
  Transform inverse() const { return {inv_, m_}; }
  const Matrix4& matrix() const { return m_; }
  const Matrix4& inverse_matrix() const { return inv_; }

  Vec3 point(Vec3 p) const;
  Vec3 vector(Vec3 v) const;
  // Normals transform by the inverse transpose.
  Vec3 normal(Vec3 n) const;
  bool swaps_handedness() const;
  bool is_identity() const { return m_ == matrix_identity(); }
  // True when the linear part is a rotation times a uniform scale (returned in *s).
  bool is_similarity(float* s = nullptr) const;

 private:
  Matrix4 m_, inv_;
};

}  // namespace bpm
