#include "base/transform.h"

#include <cmath>

namespace bpm {

Matrix4 matrix_identity() {
  Matrix4 m{};
  for (int i = 0; i < 4; ++i) m[i][i] = 1;
  return m;
}

Matrix4 matrix_multiply(const Matrix4& a, const Matrix4& b) {
  Matrix4 r{};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 4; ++k) r[i][j] += a[i][k] * b[k][j];
  return r;
}

Matrix4 matrix_transpose(const Matrix4& m) {
  Matrix4 r{};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) r[i][j] = m[j][i];
  return r;
}

// Gauss-Jordan elimination with partial pivoting.
std::optional<Matrix4> matrix_inverse(const Matrix4& m) {
  Matrix4 a = m, inv = matrix_identity();
  for (int c = 0; c < 4; ++c) {
    int pivot = c;
    for (int r = c + 1; r < 4; ++r)
      if (std::fabs(a[r][c]) > std::fabs(a[pivot][c])) pivot = r;
    if (std::fabs(a[pivot][c]) < 1e-300) return std::nullopt;
    std::swap(a[c], a[pivot]);
    std::swap(inv[c], inv[pivot]);
    double d = 1.0 / a[c][c];
    for (int j = 0; j < 4; ++j) {
      a[c][j] *= d;
      inv[c][j] *= d;
    }
    for (int r = 0; r < 4; ++r) {
      if (r == c) continue;
      double f = a[r][c];
      for (int j = 0; j < 4; ++j) {
        a[r][j] -= f * a[c][j];
        inv[r][j] -= f * inv[c][j];
      }
    }
  }
  for (auto& row : inv)
    for (double v : row)
      if (!std::isfinite(v)) return std::nullopt;
  return inv;
}

std::optional<Transform> Transform::from_matrix(const Matrix4& m) {
  auto inv = matrix_inverse(m);
  if (!inv) return std::nullopt;
  return Transform(m, *inv);
}

Transform Transform::translate(Vec3 d) {
  Matrix4 m = matrix_identity(), inv = matrix_identity();
  for (int i = 0; i < 3; ++i) {
    m[i][3] = d[i];
    inv[i][3] = -d[i];
  }
  return {m, inv};
}

Transform Transform::scale(Vec3 s) {
  Matrix4 m = matrix_identity(), inv = matrix_identity();
  for (int i = 0; i < 3; ++i) {
    m[i][i] = s[i];
    inv[i][i] = 1.0 / s[i];
  }
  return {m, inv};
}

Transform Transform::rotate(float angle_degrees, Vec3 axis_in) {
  double len = std::sqrt(double(axis_in.x) * axis_in.x + double(axis_in.y) * axis_in.y +
                         double(axis_in.z) * axis_in.z);
  double a[3] = {axis_in.x / len, axis_in.y / len, axis_in.z / len};
  double theta = angle_degrees * M_PI / 180.0;
  double s = std::sin(theta), c = std::cos(theta);
  Matrix4 m = matrix_identity();
  m[0][0] = a[0] * a[0] + (1 - a[0] * a[0]) * c;
  m[0][1] = a[0] * a[1] * (1 - c) - a[2] * s;
  m[0][2] = a[0] * a[2] * (1 - c) + a[1] * s;
  m[1][0] = a[0] * a[1] * (1 - c) + a[2] * s;
  m[1][1] = a[1] * a[1] + (1 - a[1] * a[1]) * c;
  m[1][2] = a[1] * a[2] * (1 - c) - a[0] * s;
  m[2][0] = a[0] * a[2] * (1 - c) - a[1] * s;
  m[2][1] = a[1] * a[2] * (1 - c) + a[0] * s;
  m[2][2] = a[2] * a[2] + (1 - a[2] * a[2]) * c;
  return {m, matrix_transpose(m)};
}

std::optional<Transform> Transform::look_at(Vec3 eye, Vec3 look, Vec3 up) {
  Vec3 dir = look - eye;
  if (length(dir) == 0 || length(up) == 0) return std::nullopt;
  dir = normalize(dir);
  Vec3 right = cross(normalize(up), dir);
  if (length(right) == 0) return std::nullopt;
  right = normalize(right);
  Vec3 new_up = cross(dir, right);
  Matrix4 world_from_camera = matrix_identity();
  for (int i = 0; i < 3; ++i) {
    world_from_camera[i][0] = right[i];
    world_from_camera[i][1] = new_up[i];
    world_from_camera[i][2] = dir[i];
    world_from_camera[i][3] = eye[i];
  }
  auto inv = matrix_inverse(world_from_camera);
  if (!inv) return std::nullopt;
  return Transform(*inv, world_from_camera);
}

Transform Transform::operator*(const Transform& o) const {
  return {matrix_multiply(m_, o.m_), matrix_multiply(o.inv_, inv_)};
}

Vec3 Transform::point(Vec3 p) const {
  double r[4];
  for (int i = 0; i < 4; ++i) r[i] = m_[i][0] * p.x + m_[i][1] * p.y + m_[i][2] * p.z + m_[i][3];
  if (r[3] != 1 && r[3] != 0)
    return Vec3(float(r[0] / r[3]), float(r[1] / r[3]), float(r[2] / r[3]));
  return Vec3(float(r[0]), float(r[1]), float(r[2]));
}

Vec3 Transform::vector(Vec3 v) const {
  return Vec3(float(m_[0][0] * v.x + m_[0][1] * v.y + m_[0][2] * v.z),
              float(m_[1][0] * v.x + m_[1][1] * v.y + m_[1][2] * v.z),
              float(m_[2][0] * v.x + m_[2][1] * v.y + m_[2][2] * v.z));
}

Vec3 Transform::normal(Vec3 n) const {
  return Vec3(float(inv_[0][0] * n.x + inv_[1][0] * n.y + inv_[2][0] * n.z),
              float(inv_[0][1] * n.x + inv_[1][1] * n.y + inv_[2][1] * n.z),
              float(inv_[0][2] * n.x + inv_[1][2] * n.y + inv_[2][2] * n.z));
}

bool Transform::swaps_handedness() const {
  double det = m_[0][0] * (m_[1][1] * m_[2][2] - m_[1][2] * m_[2][1]) -
               m_[0][1] * (m_[1][0] * m_[2][2] - m_[1][2] * m_[2][0]) +
               m_[0][2] * (m_[1][0] * m_[2][1] - m_[1][1] * m_[2][0]);
  return det < 0;
}

bool Transform::is_similarity(float* s_out) const {
  double len[3], dots[3];
  for (int c = 0; c < 3; ++c)
    len[c] = std::sqrt(m_[0][c] * m_[0][c] + m_[1][c] * m_[1][c] + m_[2][c] * m_[2][c]);
  auto col_dot = [&](int a, int b) {
    return m_[0][a] * m_[0][b] + m_[1][a] * m_[1][b] + m_[2][a] * m_[2][b];
  };
  dots[0] = col_dot(0, 1);
  dots[1] = col_dot(0, 2);
  dots[2] = col_dot(1, 2);
  double s = len[0];
  bool ok = std::fabs(len[1] - s) <= 1e-5 * s && std::fabs(len[2] - s) <= 1e-5 * s &&
            m_[3][0] == 0 && m_[3][1] == 0 && m_[3][2] == 0 && m_[3][3] == 1;
  for (double d : dots) ok = ok && std::fabs(d) <= 1e-5 * s * s;
  if (s_out) *s_out = float(s);
  return ok;
}

}  // namespace bpm
