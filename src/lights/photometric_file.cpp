#include "lights/photometric_file.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <sstream>

#include "base/sampling.h"
#include "base/text.h"

namespace bpm {
namespace {

constexpr double kDegrees = 180.0 / 3.14159265358979323846;

std::vector<std::string> split_lines(const std::string& text) {
  std::vector<std::string> lines;
  std::string line;
  std::istringstream in(text);
  while (std::getline(in, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    lines.push_back(line);
  }
  return lines;
}

std::string trim(const std::string& s) {
  size_t a = s.find_first_not_of(" \t\r\n"), b = s.find_last_not_of(" \t\r\n");
  return a == std::string::npos ? "" : s.substr(a, b - a + 1);
}

std::string upper(std::string s) {
  for (char& c : s) c = char(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// A number and where it stands.
struct Token {
  std::string text;
  int line = 0, column = 0;
};

// The photometric planes as a file stores them, unfolded to [0, 360] by the symmetries it
// declares: each mirror maps a stored angle to another (degrees), keeping its row.
struct Planes {
  std::map<double, std::vector<double>> rows;  // C -> intensities over gamma
  void add(double c, const std::vector<double>& row) {
    c = std::fmod(c + 720.0, 360.0);
    if (std::fabs(c) < 1e-9 || std::fabs(c - 360) < 1e-9) c = 0;
    rows.emplace(c, row);  // a plane given twice keeps the first
  }
  void mirror(const std::function<double(double)>& f) {
    const auto stored = rows;
    for (const auto& [c, row] : stored) add(f(c), row);
  }
  // Whether a plane lies at C = 0 (the table needs one: it wraps from 360 back to it).
  bool covers_zero() const { return !rows.empty() && rows.begin()->first == 0; }
  // The table over [0, 360] with the plane at 0 repeated at 360.
  void to_table(PhotometricData* d) const {
    d->c.clear();
    d->candela.clear();
    for (const auto& [c, row] : rows) {
      d->c.push_back(c);
      d->candela.insert(d->candela.end(), row.begin(), row.end());
    }
    d->c.push_back(360);
    const std::vector<double>& first = rows.begin()->second;
    d->candela.insert(d->candela.end(), first.begin(), first.end());
  }
};

// ---- IES LM-63 ----

class IesReader {
 public:
  IesReader(const std::string& text, const std::string& path)
      : lines_(split_lines(text)), path_(path) {}
  PhotometricData read();

 private:
  [[noreturn]] void fail(int line, int column, const std::string& what) const {
    throw Error(FileLoc{path_, line, column}, what);
  }
  [[noreturn]] void fail(const Token& t, const std::string& what) const {
    fail(t.line, t.column, what);
  }
  size_t read_header(PhotometricData* d);  // up to TILT=; returns the index of the next line
  void tokenize(size_t first_line);
  const Token& next(const std::string& what);
  double number(const std::string& what, const Token** where = nullptr);
  int count(const std::string& what, int least, int most);
  std::vector<double> angles(int n, double lo, double hi, const std::string& what);
  void unfold(const std::vector<double>& h, const std::vector<std::vector<double>>& rows,
              const Token& h_first, PhotometricData* d) const;

  std::vector<std::string> lines_;
  std::string path_;
  std::vector<Token> tokens_;
  size_t next_ = 0;
};

size_t IesReader::read_header(PhotometricData* d) {
  if (lines_.empty()) fail(1, 1, "empty photometric file: an IES file starts with its header");
  const std::string first = upper(trim(lines_[0]));
  if (first.rfind("IESNA:LM-63-", 0) == 0 || first.rfind("IES:LM-63-", 0) == 0)
    d->format = "IES LM-63-" + first.substr(first.find("LM-63-") + 6);
  else if (first.rfind("IESNA91", 0) == 0)
    d->format = "IES LM-63-1991";
  else
    d->format = "IES LM-63-1986";
  for (size_t i = 0; i < lines_.size(); ++i) {
    const std::string line = trim(lines_[i]);
    const std::string key = upper(line);
    if (key.rfind("[LUMINAIRE]", 0) == 0 || (d->name.empty() && key.rfind("[LUMCAT]", 0) == 0))
      d->name = trim(line.substr(line.find(']') + 1));
    if (key.rfind("TILT", 0) != 0) continue;
    const size_t eq = line.find('=');
    const std::string tilt = eq == std::string::npos ? "" : upper(trim(line.substr(eq + 1)));
    if (tilt != "NONE")
      fail(int(i + 1), 1,
           "\"" + line +
               "\": tilt data is not supported (only TILT=NONE: the luminaire measured as it is "
               "mounted)");
    return i + 1;
  }
  fail(int(lines_.size()), 1, "no TILT= line: this is not an IES LM-63 file");
}

void IesReader::tokenize(size_t first_line) {
  for (size_t i = first_line; i < lines_.size(); ++i) {
    for (Word& w : split_words(lines_[i], ","))
      tokens_.push_back({std::move(w.text), int(i + 1), w.column});
  }
}

const Token& IesReader::next(const std::string& what) {
  if (next_ >= tokens_.size()) fail(int(lines_.size()), 1, "the file ends before " + what);
  return tokens_[next_++];
}

double IesReader::number(const std::string& what, const Token** where) {
  const Token& t = next(what);
  double v;
  if (!parse_number(t.text, &v)) fail(t, what + ": \"" + t.text + "\" is not a number");
  if (where) *where = &t;
  return v;
}

int IesReader::count(const std::string& what, int least, int most) {
  const Token* t;
  double v = number(what, &t);
  if (v != std::floor(v) || v < least || v > most)
    fail(*t, what + " must be a whole number from " + std::to_string(least) + " to " +
                 std::to_string(most) + ", not " + t->text);
  return int(v);
}

std::vector<double> IesReader::angles(int n, double lo, double hi, const std::string& what) {
  std::vector<double> a;
  for (int i = 0; i < n; ++i) {
    const Token* t;
    double v = number(what, &t);
    if (v < lo - 1e-9 || v > hi + 1e-9)
      fail(*t, what + " " + t->text + " is outside " + std::to_string(int(lo)) + " to " +
                   std::to_string(int(hi)) + " degrees");
    if (!a.empty() && !(v > a.back()))
      fail(*t, what + " must increase: " + t->text + " follows " + std::to_string(a.back()));
    a.push_back(v);
  }
  return a;
}

// The symmetry a type C file declares by its horizontal angles (LM-63-2002, section 5.1).
void IesReader::unfold(const std::vector<double>& h, const std::vector<std::vector<double>>& rows,
                       const Token& h_first, PhotometricData* d) const {
  Planes p;
  for (size_t i = 0; i < h.size(); ++i) p.add(h[i], rows[i]);
  const double first = h.front(), last = h.back();
  if (first == 0 && last == 0) {
    // Rotationally symmetric: one plane.
  } else if (first == 0 && last == 90) {
    p.mirror([](double c) { return 180 - c; });
    p.mirror([](double c) { return 360 - c; });
  } else if (first == 0 && last == 180) {
    p.mirror([](double c) { return 360 - c; });
  } else if (first == 0 && last > 180 && last <= 360) {
    // No symmetry; between the last plane and 360 the intensity goes back to the plane at 0.
  } else if (first == 90 && last == 270) {
    p.mirror([](double c) { return 180 - c; });  // symmetric about the 90-270 plane (1995)
  } else {
    fail(h_first, "horizontal angles from " + std::to_string(first) + " to " +
                      std::to_string(last) +
                      " degrees declare no type C symmetry (0 to 0, 90, 180 or up to 360; or 90 "
                      "to 270)");
  }
  if (!p.covers_zero())
    fail(h_first, "the horizontal angles leave no plane at C = 0 once unfolded");
  p.to_table(d);
}

PhotometricData IesReader::read() {
  PhotometricData d;
  d.path = path_;
  tokenize(read_header(&d));
  const int lamps = count("the number of lamps", 1, 1000000);
  const Token* t;
  const double lumens = number("the lumens per lamp", &t);
  if (!(lumens > 0) && lumens != -1)
    fail(*t, "lumens per lamp must be positive, or -1 for absolute photometry; not " + t->text);
  const double multiplier = number("the candela multiplier", &t);
  if (!(multiplier > 0)) fail(*t, "the candela multiplier must be positive, not " + t->text);
  const int n_v = count("the number of vertical angles", 2, 100000);
  const int n_h = count("the number of horizontal angles", 1, 100000);
  const Token& type_token = next("the photometric type");
  --next_;
  const int type = count("the photometric type (1 C, 2 B, 3 A)", 1, 3);
  if (type != 1)
    fail(type_token, std::string("type ") + (type == 2 ? "B" : "A") +
                         " photometry is not supported (only type C, photometric type 1)");
  count("the units type (1 feet, 2 metres)", 1, 2);
  for (const char* what : {"the luminous opening's width", "its length", "its height"})
    number(what);
  const double ballast = number("the ballast factor", &t);
  if (!(ballast > 0)) fail(*t, "the ballast factor must be positive, not " + t->text);
  // 1995 and earlier: the ballast-lamp photometric factor, which scales the candela values; 2002:
  // "future use" (1); 2019: the file generation type, a code (1.00001 to 1.11011) that says how
  // the file was made and scales nothing.
  const double lamp_factor = number("the ballast-lamp photometric factor", &t);
  if (!(lamp_factor > 0))
    fail(*t,
         "the ballast-lamp factor (or future use, or file generation type) must be "
         "positive, not " +
             t->text);
  const bool scales = d.format < "IES LM-63-2002";
  number("the input watts");
  // Counted before anything is allocated for them: a header may claim any size.
  const uint64_t values = uint64_t(n_v) + uint64_t(n_h) + uint64_t(n_v) * uint64_t(n_h);
  if (tokens_.size() - next_ < values)
    fail(int(lines_.size()), 1,
         "the file ends before its " + std::to_string(n_h) + " x " + std::to_string(n_v) +
             " candela values and their angles (" + std::to_string(tokens_.size() - next_) +
             " numbers left)");
  d.gamma = angles(n_v, 0, 180, "vertical angle");
  const Token& h_first = next("the horizontal angles");
  --next_;
  const std::vector<double> h = angles(n_h, 0, 360, "horizontal angle");
  std::vector<std::vector<double>> rows(size_t(n_h), std::vector<double>(size_t(n_v), 0.0));
  for (auto& row : rows)
    for (double& v : row) {
      v = number("the candela values", &t);
      if (v < 0) fail(*t, "a candela value must not be negative: " + t->text);
      v *= multiplier * ballast * (scales ? lamp_factor : 1);
      if (!(v <= 3e38))
        fail(*t, "the candela value " + t->text + " times the multipliers is too large");
    }
  if (next_ < tokens_.size())
    fail(tokens_[next_], "\"" + tokens_[next_].text + "\" after the candela table (" +
                             std::to_string(n_h) + " x " + std::to_string(n_v) + " values)");
  unfold(h, rows, h_first, &d);
  d.lamp_lumens = lumens > 0 ? lamps * lumens : 0;
  return d;
}

// ---- EULUMDAT ----

class EulumdatReader {
 public:
  EulumdatReader(const std::string& text, const std::string& path)
      : lines_(split_lines(text)), path_(path) {}
  PhotometricData read();

 private:
  [[noreturn]] void fail(int line, const std::string& what) const {
    throw Error(FileLoc{path_, line, 1}, what);
  }
  const std::string& line(int n, const std::string& what) const {
    if (n > int(lines_.size()))
      fail(int(lines_.size()), "the file ends before line " + std::to_string(n) + " (" + what +
                                   "): is this a EULUMDAT file?");
    return lines_[size_t(n - 1)];
  }
  double number(int n, const std::string& what) const {
    double v;
    const std::string text = trim(line(n, what));
    if (!parse_number(text, &v)) fail(n, what + ": \"" + text + "\" is not a number");
    return v;
  }
  int whole(int n, const std::string& what, int lo, int hi) const {
    double v = number(n, what);
    if (v != std::floor(v) || v < lo || v > hi)
      fail(n, what + " must be a whole number from " + std::to_string(lo) + " to " +
                  std::to_string(hi));
    return int(v);
  }

  std::vector<std::string> lines_;
  std::string path_;
};

PhotometricData EulumdatReader::read() {
  PhotometricData d;
  d.path = path_;
  d.format = "EULUMDAT";
  const int isym = whole(3, "the symmetry indicator Isym", 0, 4);
  const int mc = whole(4, "the number of C planes Mc", 1, 100000);
  const int ng = whole(6, "the number of intensities per plane Ng", 2, 100000);
  d.name = trim(line(9, "the luminaire's name"));
  const double conversion = number(24, "the conversion factor for intensities");
  if (!(conversion > 0)) fail(24, "the conversion factor for intensities must be positive");
  const int sets = whole(26, "the number of lamp sets", 1, 1000);
  // Lines 26a to 26f, each one line per lamp set: numbers of lamps, types, fluxes, colour
  // temperatures, colour rendering, wattages. The first set's flux scales the intensities.
  const int flux_line = 27 + 2 * sets;
  const double flux = number(flux_line, "the lamps' total luminous flux");
  if (!(flux > 0)) fail(flux_line, "the lamps' luminous flux must be positive");
  int at = 27 + 6 * sets + 10;  // after the ten direct ratios
  if ((isym == 2 && mc % 2) || ((isym == 3 || isym == 4) && mc % 4))
    fail(4, "Mc = " + std::to_string(mc) +
                " C planes cannot have the symmetry Isym = " + std::to_string(isym));
  std::vector<double> c(size_t(mc), 0.0), gamma(size_t(ng), 0.0);
  for (int i = 0; i < mc; ++i) {
    c[size_t(i)] = number(at + i, "C angle");
    if (c[size_t(i)] < 0 || c[size_t(i)] >= 360)
      fail(at + i, "C angles must lie in 0 to 360 degrees (360 excluded)");
    if (i > 0 && !(c[size_t(i)] > c[size_t(i) - 1])) fail(at + i, "C angles must increase");
  }
  at += mc;
  for (int j = 0; j < ng; ++j) {
    gamma[size_t(j)] = number(at + j, "gamma angle");
    if (gamma[size_t(j)] < 0 || gamma[size_t(j)] > 180)
      fail(at + j, "gamma angles must lie in 0 to 180 degrees");
    if (j > 0 && !(gamma[size_t(j)] > gamma[size_t(j) - 1]))
      fail(at + j, "gamma angles must increase");
  }
  at += ng;
  // The stored planes (1-based, as the format's description gives them).
  int mc1 = 1, mc2 = mc;
  if (isym == 1) mc2 = 1;
  if (isym == 2) mc2 = mc / 2 + 1;
  if (isym == 3) mc1 = 3 * mc / 4 + 1, mc2 = mc1 + mc / 2;
  if (isym == 4) mc2 = mc / 4 + 1;
  Planes p;
  const double scale = conversion * flux / 1000;  // cd/klm to cd
  for (int k = mc1; k <= mc2; ++k) {
    std::vector<double> row(static_cast<size_t>(ng), 0.0);
    for (int j = 0; j < ng; ++j, ++at) {
      row[size_t(j)] = number(at, "intensity (cd/klm)");
      if (row[size_t(j)] < 0) fail(at, "an intensity must not be negative");
      row[size_t(j)] *= scale;
      if (!(row[size_t(j)] <= 3e38)) fail(at, "an intensity times the lamp flux is too large");
    }
    p.add(c[size_t((k - 1) % mc)], row);
  }
  for (int n = at; n <= int(lines_.size()); ++n)
    if (!trim(lines_[size_t(n - 1)]).empty())
      fail(n, "\"" + trim(lines_[size_t(n - 1)]) + "\" after the intensity table");
  const int c_line = 27 + 6 * sets + 10;
  if (isym == 2) p.mirror([](double a) { return 360 - a; });
  if (isym == 3) p.mirror([](double a) { return 180 - a; });
  if (isym == 4) {
    p.mirror([](double a) { return 180 - a; });
    p.mirror([](double a) { return 360 - a; });
  }
  if (!p.covers_zero()) fail(c_line, "the stored C planes leave no plane at C = 0 once unfolded");
  d.gamma = gamma;
  p.to_table(&d);
  d.lamp_lumens = flux;
  return d;
}

size_t upper_index(const std::vector<double>& a, double x) {
  return size_t(std::upper_bound(a.begin(), a.end(), x) - a.begin());
}

}  // namespace

double PhotometricData::intensity(double c_deg, double gamma_deg) const {
  const double g0 = gamma.front(), g1 = gamma.back();
  if (gamma_deg < g0 - 1e-9 || gamma_deg > g1 + 1e-9) return 0;
  gamma_deg = std::clamp(gamma_deg, g0, g1);
  c_deg = std::fmod(c_deg, 360.0);
  if (c_deg < 0) c_deg += 360;
  const size_t n = gamma.size();
  const size_t j = std::min(std::max<size_t>(upper_index(gamma, gamma_deg), 1), n - 1);
  const double tg = (gamma_deg - gamma[j - 1]) / (gamma[j] - gamma[j - 1]);
  const size_t i = std::min(std::max<size_t>(upper_index(c, c_deg), 1), c.size() - 1);
  const double tc = (c_deg - c[i - 1]) / (c[i] - c[i - 1]);
  auto at = [&](size_t ci, size_t gj) { return candela[ci * n + gj]; };
  const double lo = at(i - 1, j - 1) * (1 - tg) + at(i - 1, j) * tg;
  const double hi = at(i, j - 1) * (1 - tg) + at(i, j) * tg;
  return lo * (1 - tc) + hi * tc;
}

double PhotometricData::intensity(Vec3 w) const {
  const double cos_gamma = std::clamp(-double(w.y), -1.0, 1.0);
  double c_deg = std::atan2(double(w.z), double(w.x)) * kDegrees;
  return intensity(c_deg, std::acos(cos_gamma) * kDegrees);
}

double PhotometricData::luminous_flux() const {
  // The midpoint rule over 0.25 x 0.25 degree cells: the table's bilinear intensity varies
  // smoothly within them.
  constexpr int kC = 1440, kGamma = 720;
  const double dc = 2 * 3.14159265358979323846 / kC, dg = 3.14159265358979323846 / kGamma;
  double sum = 0;
  for (int j = 0; j < kGamma; ++j) {
    const double g = (j + 0.5) * dg;
    double ring = 0;
    for (int i = 0; i < kC; ++i) ring += intensity((i + 0.5) * dc * kDegrees, g * kDegrees);
    sum += ring * std::sin(g);
  }
  return sum * dc * dg;
}

PhotometricData parse_ies(const std::string& text, const std::string& path) {
  return IesReader(text, path).read();
}
PhotometricData read_ies(const std::string& path) {
  return parse_ies(read_text_file(path, "photometric file"), path);
}
PhotometricData parse_eulumdat(const std::string& text, const std::string& path) {
  return EulumdatReader(text, path).read();
}
PhotometricData read_eulumdat(const std::string& path) {
  return parse_eulumdat(read_text_file(path, "photometric file"), path);
}

bool is_photometric_file(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  if (dot == std::string::npos) return false;
  const std::string ext = upper(path.substr(dot + 1));
  return ext == "IES" || ext == "LDT";
}

PhotometricData read_photometric_file(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const std::string ext = dot == std::string::npos ? "" : upper(path.substr(dot + 1));
  if (ext == "IES") return read_ies(path);
  if (ext == "LDT") return read_eulumdat(path);
  throw Error("\"" + path + "\" is not a photometric file (.ies or .ldt)");
}

Vec3 goniometric_image_direction(Vec2 uv) {
  // pbrt-v4's goniometric light swaps y and z between its frame and the image's sphere.
  const Vec3 s = equal_area_square_to_sphere(uv);
  return {s.x, s.z, s.y};
}

std::vector<float> goniometric_image(const PhotometricData& d, int n) {
  std::vector<float> image(size_t(n) * size_t(n));
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const Vec2 uv{(x + 0.5f) / float(n), (y + 0.5f) / float(n)};
      image[size_t(y) * size_t(n) + size_t(x)] =
          float(d.intensity(goniometric_image_direction(uv)));
    }
  return image;
}

}  // namespace bpm
