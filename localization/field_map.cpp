#include "localization/field_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/atomic_file.hpp"

namespace omniloc {

FieldMap::FieldMap(const Field& field, double cell, const std::string& cache_dir) : cell_(cell), fingerprint_(field.fingerprint()) {
  // Cover the floor inside the walls plus a cell.
  const double hx = field.half_floor_x() + cell, hy = field.half_floor_y() + cell;
  nx_ = static_cast<int>(std::ceil(2 * hx / cell)) + 1;
  ny_ = static_cast<int>(std::ceil(2 * hy / cell)) + 1;
  x0_ = -hx;
  y0_ = -hy;
  std::ostringstream name;
  name << "fieldmap_" << fingerprint_ << "_" << std::lround(cell * 1e4) << ".bin";
  const std::string file = cache_dir.empty() ? "" : (std::filesystem::path(cache_dir) / name.str()).string();
  // Cache: a header naming field, cell and size, then the floats. A mismatching file is rebuilt.
  std::ostringstream header;
  header << "omniloc-fieldmap 1 " << fingerprint_ << " " << cell << " " << nx_ << " " << ny_ << "\n";
  if (!file.empty() && std::filesystem::exists(file)) {
    std::ifstream in(file, std::ios::binary);
    std::string line;
    std::getline(in, line);
    if (line + "\n" == header.str()) {
      grid_.resize(static_cast<std::size_t>(nx_) * ny_);
      in.read(reinterpret_cast<char*>(grid_.data()), static_cast<std::streamsize>(grid_.size() * sizeof(float)));
      if (in.gcount() == static_cast<std::streamsize>(grid_.size() * sizeof(float))) {
        from_cache_ = true;
        return;
      }
    }
  }
  grid_.resize(static_cast<std::size_t>(nx_) * ny_);
  for (int j = 0; j < ny_; ++j)
    for (int i = 0; i < nx_; ++i) grid_[static_cast<std::size_t>(j) * nx_ + i] = static_cast<float>(field.distance_to_marking({x0_ + i * cell, y0_ + j * cell}));
  if (!file.empty()) {
    std::string out = header.str();
    out.append(reinterpret_cast<const char*>(grid_.data()), grid_.size() * sizeof(float));
    try {
      write_file_atomic(file, out);
    } catch (const std::exception&) {
      // A read-only cache folder only costs the rebuild next time.
    }
  }
}

double FieldMap::distance(const Eigen::Vector2d& p) const { return distance(p, nullptr); }

void FieldMap::off_table(double dx, double dy, double* d, Eigen::Vector2d* g) const {
  // Same arithmetic as before the fast path was split off, so results stay byte-identical.
  const double out = std::hypot(dx * cell_, dy * cell_);
  if (out > 0) {
    *d += out;  // off the table: farther from everything
    if (g) *g = Eigen::Vector2d(dx * cell_, dy * cell_) / out;
  }
}

}  // namespace omniloc
