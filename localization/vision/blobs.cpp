#include "localization/vision/blobs.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <tuple>
#include <utility>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "core/angles.hpp"

namespace omniloc {

namespace {

const std::vector<std::string> kBlobColourNames = {"yellow", "blue", "red"};

std::vector<ColourClass> to_classes(const std::vector<std::string>& names) {
  std::vector<ColourClass> out;
  for (const auto& n : names) {
    const ColourClass c = landmark_colour_class(n);
    if (std::find(out.begin(), out.end(), c) == out.end()) out.push_back(c);
  }
  return out;
}

// Class buffer values besides the colour classes (all below kNumClasses): a pixel not classified yet,
// a pixel outside the searched annulus (reads as kUnknown), and a flag on pixels already put in a
// component.
constexpr std::uint8_t kUnclassified = 0xFF;
constexpr std::uint8_t kOutside = 0xFE;
constexpr std::uint8_t kVisited = 0x80;
static_assert(kNumClasses < kVisited);

// A row's run of component pixels, u0 .. u1 inclusive.
struct Span {
  int v, u0, u1;
};

// Per-region accumulators.
struct Region {
  double ref = 0.0;                 // reference bearing (centroid), radians
  double dmin = 0.0, dmax = 0.0;    // extent relative to ref, radians
  float rmin = std::numeric_limits<float>::max(), rmax = 0.0f;
  int imin = -1;                    // pixel index of the nearest pixel
};

// Row spacing R and column spacing C of the classified grid: the pixels between grid lines form
// (R - 1) x (C - 1) cells, which must hold fewer than min_area pixels; of those, the spacing with
// the fewest grid pixels.
std::pair<int, int> grid_spacing(int min_area) {
  std::pair<int, int> best{1, 1};  // everything
  double best_fraction = 1.0;
  for (int r = 2; r <= 64; ++r) {
    const int c = (min_area - 1) / (r - 1) + 1;
    if (c < 2) break;
    const double fraction = 1.0 - static_cast<double>((r - 1) * (c - 1)) / (r * c);
    if (fraction < best_fraction) {
      best_fraction = fraction;
      best = {r, c};
    }
  }
  return best;
}

// The colour table's cell index as a sum of per-channel terms from small tables (3 KB, stays in L1):
// three loads and two ors per pixel instead of three shifts and masks each, in the grid pass that
// classifies a third of the frame.
struct GridLookup {
  std::array<std::uint32_t, 3 * 256> terms;
  const std::uint8_t* lut;
  explicit GridLookup(const ColourTable::Lookup& l) : lut(l.lut) {
    for (int x = 0; x < 256; ++x) {
      terms[x] = static_cast<std::uint32_t>((x >> l.shift) << (2 * l.bits));
      terms[256 + x] = static_cast<std::uint32_t>((x >> l.shift) << l.bits);
      terms[512 + x] = static_cast<std::uint32_t>(x >> l.shift);
    }
  }
};

// Classifies the grid of BlobDetector::detect(): grid rows whole, other rows every grid_cols-th
// pixel (the same columns in every row), the rest of the annulus kUnclassified, outside it kOutside.
// Notes a seed per run of a wanted colour along a grid row, per wanted pixel on a grid column, in
// raster order. Arguments rather than members: stores through the byte pointers could alias
// members, which would make the compiler reload them per pixel.
void classify_grid(const GridLookup& lookup, const std::uint8_t* src, std::uint8_t* cls, int w, int h, int grid_rows, int grid_cols,
                   const std::vector<int>& row_runs, const std::vector<std::pair<int, int>>& runs, const std::array<bool, 256>& wanted,
                   std::vector<std::size_t>& seeds) {
  const std::uint32_t* const terms = lookup.terms.data();
  const std::uint8_t* const lut = lookup.lut;
  auto classify = [terms, lut](const std::uint8_t* rgb) { return lut[terms[rgb[0]] | terms[256 + rgb[1]] | terms[512 + rgb[2]]]; };
  seeds.clear();
  for (int v = 0; v < h; ++v) {
    const std::size_t base = static_cast<std::size_t>(v) * w;
    std::uint8_t* row = cls + base;
    const std::uint8_t* px = src + 3 * base;
    std::memset(row, kOutside, static_cast<std::size_t>(w));
    const bool full = v % grid_rows == 0;
    for (int k = row_runs[v]; k < row_runs[v + 1]; ++k) {
      const auto [u0, u1] = runs[k];
      if (full) {
        std::uint8_t prev = kOutside;
        for (int u = u0; u < u1; ++u) {
          const std::uint8_t c = classify(px + 3 * u);
          row[u] = c;
          if (wanted[c] && c != prev) seeds.push_back(base + u);
          prev = c;
        }
      } else {
        std::memset(row + u0, kUnclassified, static_cast<std::size_t>(u1 - u0));
        for (int u = (u0 + grid_cols - 1) / grid_cols * grid_cols; u < u1; u += grid_cols) {
          const std::uint8_t c = classify(px + 3 * u);
          row[u] = c;
          if (wanted[c]) seeds.push_back(base + u);
        }
      }
    }
  }
}

// wrap_angle() without its fmod when the angle is within (-pi, pi) already, as differences of a
// region's bearings nearly always are: fmod returns its argument exactly then, so the result is
// wrap_angle()'s to the bit.
inline double wrap_near(double a) {
  const double x = a + kPi;
  if (x > 0.0 && x < kTwoPi) return x - kPi;
  return wrap_angle(a);
}

}  // namespace

BlobParams BlobParams::from_json(JsonReader& r) {
  BlobParams p;
  p.colours = to_classes(r.strings("colours", kBlobColourNames, kBlobColourNames));
  if (r.has("edge_colours")) p.edge_colours = to_classes(r.strings("edge_colours", std::nullopt, kBlobColourNames));
  read_params(r, p, params());
  return p;
}

const ParamList<BlobParams>& BlobParams::params() {
  using P = BlobParams;
  static const ParamList<P> list = {
      integer_param("min_area_px", &P::min_area_px, 1, 1000000, "smaller regions (pixels) are ignored"),
      number_param("outer_radius_px", &P::outer_radius_px, 0.0, 100000.0, "px", "pixels searched out to this radius; 0 = the image's inscribed circle"),
      number_param("dark_mean", &P::dark_mean, 0.0, 255.0, "grey level", "mean grey of the annulus below this: camera covered, no blobs"),
      number_param("edge_extend_px", &P::edge_extend_px, 0.0, 10.0, "px", "widening of a region's angular extent on each side (0 by measurement)"),
      integer_param("edge_band_px", &P::edge_band_px, 1, 50, "pixels beyond an edge checked for an occluder"),
      number_param("occluded_fraction", &P::occluded_fraction, 0.0, 1.0, "", "fraction of those pixels that must be black (or off-image) for an occluded edge"),
      number_param("edge_contact_deg", &P::edge_contact_deg, 0.0, 45.0, "deg", "an edge's distance: nearest region pixel within this angle of it"),
  };
  return list;
}

struct BlobDetector::Component {
  ColourClass colour = kUnknown;
  int area = 0;
  std::int64_t sum_u = 0, sum_v = 0;  // of pixel coordinates, for the centroid
  std::vector<Span> spans;
  /// Empties the component for a new region of `c` (keeps the spans' storage).
  void start(ColourClass c) {
    colour = c;
    area = 0;
    sum_u = sum_v = 0;
    spans.clear();
  }
  void add(int v, int u0, int u1) {
    const int n = u1 - u0 + 1;
    spans.push_back({v, u0, u1});
    area += n;
    sum_u += static_cast<std::int64_t>(u0 + u1) * n / 2;
    sum_v += static_cast<std::int64_t>(v) * n;
  }
};

BlobDetector::BlobDetector(const BlobParams& p, const CalibrationMap& map, const ColourTable& table)
    : p_(p), map_(map), table_(table), w_(map.image_width()), h_(map.image_height()) {
  const std::size_t n = static_cast<std::size_t>(w_) * static_cast<std::size_t>(h_);
  bearing_.resize(n);
  radius_.resize(n);
  inside_.resize(n);
  const Eigen::Vector2d c = map.centre();
  const double outer = p.outer_radius_px > 0 ? p.outer_radius_px : 0.5 * std::min(w_, h_);
  for (int v = 0; v < h_; ++v)
    for (int u = 0; u < w_; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w_ + u;
      const double du = u + 0.5 - c.x(), dv = v + 0.5 - c.y();
      const double r = std::hypot(du, dv);
      // Image direction of bearing b is (-sin b, -cos b): forward up, left to the left.
      bearing_[i] = static_cast<float>(std::atan2(-du, -dv));
      radius_[i] = static_cast<float>(r);
      inside_[i] = r >= map.min_radius() && r <= outer;
    }
  row_runs_.assign(static_cast<std::size_t>(h_) + 1, 0);
  for (int v = 0; v < h_; ++v) {
    const std::uint8_t* in = inside_.data() + static_cast<std::size_t>(v) * w_;
    for (int u = 0; u < w_;) {
      if (!in[u]) {
        ++u;
        continue;
      }
      const int u0 = u;
      while (u < w_ && in[u]) ++u;
      runs_.emplace_back(u0, u);
    }
    row_runs_[v + 1] = static_cast<int>(runs_.size());
  }
  std::tie(grid_rows_, grid_cols_) = grid_spacing(p.min_area_px);
}

double BlobDetector::mean_grey(const Image& img) const {
  if (img.width != w_ || img.height != h_) return 0.0;
  // Every 4th pixel by index over the whole image, those in the annulus. Integer sums: the result
  // does not depend on the order, so the vector loop gives the plain loop's value exactly.
  std::uint64_t sum = 0, count = 0;
  const std::uint8_t* src = img.rgb.data();
#if defined(__SSE2__)
  // 16 pixels (48 bytes) from a sampled pixel hold 4 samples: bytes 0-2, 12-14, 24-26, 36-38.
  const __m128i m0 = _mm_setr_epi8(-1, -1, -1, 0, 0, 0, 0, 0, 0, 0, 0, 0, -1, -1, -1, 0);
  const __m128i m1 = _mm_setr_epi8(0, 0, 0, 0, 0, 0, 0, 0, -1, -1, -1, 0, 0, 0, 0, 0);
  const __m128i m2 = _mm_setr_epi8(0, 0, 0, 0, -1, -1, -1, 0, 0, 0, 0, 0, 0, 0, 0, 0);
  const __m128i zero = _mm_setzero_si128();
  __m128i acc = zero;
#endif
  for (int v = 0; v < h_; ++v)
    for (int k = row_runs_[v]; k < row_runs_[v + 1]; ++k) {
      const std::size_t i1 = static_cast<std::size_t>(v) * w_ + runs_[k].second;
      std::size_t i = (static_cast<std::size_t>(v) * w_ + runs_[k].first + 3) & ~std::size_t{3};
#if defined(__SSE2__)
      for (; i + 16 <= i1; i += 16) {
        const std::uint8_t* px = src + 3 * i;
        const __m128i a = _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(px)), m0);
        const __m128i b = _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(px + 16)), m1);
        const __m128i c = _mm_and_si128(_mm_loadu_si128(reinterpret_cast<const __m128i*>(px + 32)), m2);
        acc = _mm_add_epi64(acc, _mm_add_epi64(_mm_sad_epu8(a, zero), _mm_add_epi64(_mm_sad_epu8(b, zero), _mm_sad_epu8(c, zero))));
        count += 4;
      }
#endif
      for (; i < i1; i += 4) {
        const std::uint8_t* px = src + 3 * i;
        sum += px[0] + px[1] + px[2];
        ++count;
      }
    }
#if defined(__SSE2__)
  sum += static_cast<std::uint64_t>(_mm_cvtsi128_si64(acc)) + static_cast<std::uint64_t>(_mm_cvtsi128_si64(_mm_unpackhi_epi64(acc, acc)));
#endif
  return count ? static_cast<double>(sum) / (3.0 * static_cast<double>(count)) : 0.0;
}

void BlobDetector::measure(const Image& img, std::uint8_t* cls, const Component& comp, std::vector<Blob>& out) const {
  const std::uint8_t* src = img.rgb.data();
  const ColourTable::Lookup classify = table_.lookup();
  const Eigen::Vector2d c = map_.centre();
  auto class_at = [&](double r, double b) -> int {
    const int u = static_cast<int>(std::floor(c.x() - r * std::sin(b)));
    const int v = static_cast<int>(std::floor(c.y() - r * std::cos(b)));
    if (u < 0 || v < 0 || u >= w_ || v >= h_) return -1;
    const std::size_t i = static_cast<std::size_t>(v) * w_ + u;
    std::uint8_t k = cls[i];
    if (k == kUnclassified) k = cls[i] = classify(src + 3 * i);
    return k == kOutside ? kUnknown : k & ~kVisited;
  };
  // Whether the neighbourhood beyond an edge (direction s = +1 anticlockwise, -1 clockwise) is
  // mostly an occluder: black pixels or no image.
  auto occluded = [&](double edge, int s, const Region& g) {
    int n = 0, black = 0;
    for (double r = std::max<double>(g.rmin, map_.min_radius()); r <= g.rmax; r += 1.0)
      for (int k = 1; k <= p_.edge_band_px; ++k) {
        const int cl = class_at(r, edge + s * k / r);
        ++n;
        black += cl == -1 || cl == kObstacleBlack;
      }
    return n > 0 && black >= p_.occluded_fraction * n;
  };
  auto contact = [&](Blob& b, float rmin, int imin) {
    // The nearest pixel's inner border; hidden behind the body when it touches the inner limit.
    const double r = static_cast<double>(rmin) - 0.5;
    b.has_distance = false;
    b.distance = 0.0;
    if (imin < 0 || r <= map_.min_radius() + 1.0) return;
    if (const auto d = map_.ground_distance(r, bearing_[static_cast<std::size_t>(imin)])) {
      b.distance = *d;
      b.has_distance = true;
    }
  };
  // The nearest pixel: smallest radius, ties to the first in raster order, whatever order the
  // spans come in.
  auto nearer = [&](std::size_t i, float& rmin, int& imin) {
    if (radius_[i] < rmin || (radius_[i] == rmin && static_cast<int>(i) < imin)) {
      rmin = radius_[i];
      imin = static_cast<int>(i);
    }
  };
  auto for_each_pixel = [&](auto&& f) {
    for (const Span& s : comp.spans) {
      const std::size_t row = static_cast<std::size_t>(s.v) * w_;
      for (int u = s.u0; u <= s.u1; ++u) f(row + u);
    }
  };

  // The centroid from whole-image pixel coordinates. It is only the reference the extent is
  // measured from, yet it shows in the bearings' last bit (wrap_angle rounds the differences); it
  // was once taken relative to the bounding box of every pixel of the colour, which a speck anywhere
  // in the frame could move and which the grid search never sees.
  const double area = comp.area;
  Region g;
  g.ref = std::atan2(-(static_cast<double>(comp.sum_u) / area + 0.5 - c.x()), -(static_cast<double>(comp.sum_v) / area + 0.5 - c.y()));
  g.dmin = std::numeric_limits<double>::max();
  g.dmax = std::numeric_limits<double>::lowest();
  for_each_pixel([&](std::size_t i) {
    const double d = wrap_near(bearing_[i] - g.ref);
    const double half = p_.edge_extend_px / radius_[i];  // pixels to radians at this radius
    g.dmin = std::min(g.dmin, d - half);
    g.dmax = std::max(g.dmax, d + half);
    nearer(i, g.rmin, g.imin);
    g.rmax = std::max(g.rmax, radius_[i]);
  });
  Blob b;
  b.colour = comp.colour;
  b.kind = Blob::Kind::kRegion;
  b.left_bearing = wrap_angle(g.ref + g.dmax);
  b.right_bearing = wrap_angle(g.ref + g.dmin);
  b.bearing = wrap_angle(g.ref + 0.5 * (g.dmin + g.dmax));
  b.area_px = comp.area;
  b.left_occluded = occluded(g.ref + g.dmax, +1, g);
  b.right_occluded = occluded(g.ref + g.dmin, -1, g);
  contact(b, g.rmin, g.imin);
  out.push_back(b);
  if (std::find(p_.edge_colours.begin(), p_.edge_colours.end(), comp.colour) == p_.edge_colours.end()) return;
  // Nearest pixels close to each edge give the edges' distances.
  const double band = deg2rad(p_.edge_contact_deg);
  float rl = std::numeric_limits<float>::max(), rr = rl;
  int il = -1, ir = -1;
  for_each_pixel([&](std::size_t i) {
    const double d = wrap_near(bearing_[i] - g.ref);
    if (d >= g.dmax - band) nearer(i, rl, il);
    if (d <= g.dmin + band) nearer(i, rr, ir);
  });
  Blob left = b, right = b;
  left.kind = Blob::Kind::kLeftEdge;
  left.bearing = b.left_bearing;
  contact(left, rl, il);
  right.kind = Blob::Kind::kRightEdge;
  right.bearing = b.right_bearing;
  contact(right, rr, ir);
  out.push_back(left);
  out.push_back(right);
}

namespace {

void sort_blobs(std::vector<Blob>& out) {
  std::sort(out.begin(), out.end(), [](const Blob& a, const Blob& b) {
    if (a.colour != b.colour) return a.colour < b.colour;
    if (a.kind != b.kind) return a.kind < b.kind;
    return a.bearing < b.bearing;
  });
}

}  // namespace

bool BlobDetector::usable(const Image& img) const {
  if (img.width != w_ || img.height != h_ || img.rgb.size() < 3 * inside_.size()) return false;
  return mean_grey(img) >= p_.dark_mean;
}

std::array<bool, 256> BlobDetector::wanted_classes() const {
  std::array<bool, 256> wanted{};
  for (const ColourClass c : p_.colours) wanted[c] = true;
  return wanted;
}

std::vector<Blob> BlobDetector::detect(const Image& img) const {
  std::vector<Blob> out;
  if (!usable(img)) return out;

  // Per thread: detect() is const and may run for several robots at once; reused so that the
  // class buffer is not allocated (and page-faulted) per frame.
  thread_local std::vector<std::uint8_t> cls_buf;
  thread_local std::vector<std::size_t> seeds, stack;
  thread_local Component comp;
  cls_buf.resize(inside_.size());
  std::uint8_t* const cls = cls_buf.data();
  const std::uint8_t* const src = img.rgb.data();
  const std::array<bool, 256> wanted = wanted_classes();

  // The grid: grid rows whole, other rows every grid_cols_-th pixel (the same columns in every row),
  // the rest marked unclassified. A seed per run of a wanted colour along a grid row.
  const ColourTable::Lookup classify = table_.lookup();
  classify_grid(GridLookup(classify), src, cls, w_, h_, grid_rows_, grid_cols_, row_runs_, runs_, wanted, seeds);
  const int w = w_, h = h_;

  // Each seed's whole 8-connected component at full resolution, a row span at a time; pixels are
  // classified when first read. Components come in raster order of their first seed.
  for (const std::size_t seed : seeds) {
    if (cls[seed] & kVisited) continue;
    const std::uint8_t colour = cls[seed];
    auto is_colour = [&](std::size_t i) {
      std::uint8_t k = cls[i];
      if (k == kUnclassified) k = cls[i] = classify(src + 3 * i);
      return k == colour;
    };
    comp.start(static_cast<ColourClass>(colour));
    stack.clear();
    stack.push_back(seed);
    while (!stack.empty()) {
      const std::size_t i = stack.back();
      stack.pop_back();
      if (cls[i] != colour) continue;  // taken by an earlier span
      const int v = static_cast<int>(i / w), u = static_cast<int>(i % w);
      const std::size_t base = static_cast<std::size_t>(v) * w;
      int u0 = u, u1 = u;
      while (u0 > 0 && is_colour(base + u0 - 1)) --u0;
      while (u1 + 1 < w && is_colour(base + u1 + 1)) ++u1;
      for (int x = u0; x <= u1; ++x) cls[base + x] |= kVisited;
      comp.add(v, u0, u1);
      // 8-connected: the rows above and below, one pixel wider on each side.
      const int a = std::max(u0 - 1, 0), b = std::min(u1 + 1, w - 1);
      for (const int nv : {v - 1, v + 1}) {
        if (nv < 0 || nv >= h) continue;
        const std::size_t nbase = static_cast<std::size_t>(nv) * w;
        bool in_run = false;
        for (int x = a; x <= b; ++x) {
          const bool hit = is_colour(nbase + x);
          if (hit && !in_run) stack.push_back(nbase + x);
          in_run = hit;
        }
      }
    }
    if (comp.area >= p_.min_area_px) measure(img, cls, comp, out);
  }
  sort_blobs(out);
  return out;
}

std::vector<Blob> BlobDetector::detect_full(const Image& img) const {
  std::vector<Blob> out;
  if (!usable(img)) return out;

  // Classify the annulus once, noting each wanted colour's bounding box so connected components run
  // on that box only.
  std::vector<std::uint8_t> cls_buf(inside_.size(), kOutside);
  std::uint8_t* const cls = cls_buf.data();
  const std::array<bool, 256> wanted = wanted_classes();
  std::array<int, 256> bx0, by0, bx1, by1;
  bx0.fill(w_);
  by0.fill(h_);
  bx1.fill(-1);
  by1.fill(-1);
  for (int v = 0; v < h_; ++v)
    for (int u = 0; u < w_; ++u) {
      const std::size_t i = static_cast<std::size_t>(v) * w_ + u;
      if (!inside_[i]) continue;
      const std::uint8_t c = table_.classify(img.rgb.data() + 3 * i);
      cls[i] = c;
      if (wanted[c]) {
        bx0[c] = std::min(bx0[c], u);
        bx1[c] = std::max(bx1[c], u);
        by0[c] = std::min(by0[c], v);
        by1[c] = std::max(by1[c], v);
      }
    }
  const cv::Mat cls_mat(h_, w_, CV_8U, cls);
  cv::Mat mask, labels, stats, centroids;
  Component comp;
  for (const ColourClass colour : p_.colours) {
    if (bx1[colour] < 0) continue;  // no pixel of this colour
    const cv::Rect roi(bx0[colour], by0[colour], bx1[colour] - bx0[colour] + 1, by1[colour] - by0[colour] + 1);
    cv::compare(cls_mat(roi), cv::Scalar(colour), mask, cv::CMP_EQ);
    const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
    for (int k = 1; k < n; ++k) {
      if (stats.at<int>(k, cv::CC_STAT_AREA) < p_.min_area_px) continue;
      const int x0 = stats.at<int>(k, cv::CC_STAT_LEFT), y0 = stats.at<int>(k, cv::CC_STAT_TOP);
      const int x1 = x0 + stats.at<int>(k, cv::CC_STAT_WIDTH), y1 = y0 + stats.at<int>(k, cv::CC_STAT_HEIGHT);
      comp.start(colour);
      for (int v = y0; v < y1; ++v) {
        const int* lab = labels.ptr<int>(v);
        for (int u = x0; u < x1;) {
          if (lab[u] != k) {
            ++u;
            continue;
          }
          const int u0 = u;
          while (u < x1 && lab[u] == k) ++u;
          comp.add(v + roi.y, u0 + roi.x, u - 1 + roi.x);
        }
      }
      measure(img, cls, comp, out);
    }
  }
  sort_blobs(out);
  return out;
}

}  // namespace omniloc
