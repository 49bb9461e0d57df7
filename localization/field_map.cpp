#include "localization/field_map.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/atomic_file.hpp"
#include "core/cache_root.hpp"

namespace omniloc {

FieldMap::FieldMap(const Field& field, double cell, const std::string& cache_dir) : fingerprint_(field.fingerprint()) {
  // Cover the floor inside the walls plus a cell.
  const double hx = field.half_floor_x() + cell, hy = field.half_floor_y() + cell;
  const int nx = static_cast<int>(std::ceil(2 * hx / cell)) + 1;
  const int ny = static_cast<int>(std::ceil(2 * hy / cell)) + 1;
  const double x0 = -hx, y0 = -hy;
  grid_.resize(static_cast<std::size_t>(nx) * ny);
  table_ = Table{grid_.data(), nx, x0, y0, 1.0 / cell, cell, nx - 1.0, ny - 1.0, static_cast<unsigned>(nx - 1), static_cast<unsigned>(ny - 1)};
  std::ostringstream name;
  name << "fieldmap_" << fingerprint_ << "_" << std::lround(cell * 1e4) << ".bin";
  const std::string file = cache_dir.empty() ? "" : (std::filesystem::path(cache_dir) / name.str()).string();
  // Cache: a header naming field, cell and size, then the floats. A mismatching file is rebuilt.
  // In memory the floats are widened to doubles (no conversion per lookup): cached or computed, the
  // table holds the same float values.
  std::ostringstream header;
  header << "omniloc-fieldmap 1 " << fingerprint_ << " " << cell << " " << nx << " " << ny << "\n";
  std::error_code ec;
  if (!file.empty() && std::filesystem::is_regular_file(file, ec)) {
    std::ifstream in(file, std::ios::binary);
    std::string line;
    std::getline(in, line);
    if (line + "\n" == header.str()) {
      std::vector<float> stored(grid_.size());
      in.read(reinterpret_cast<char*>(stored.data()), static_cast<std::streamsize>(stored.size() * sizeof(float)));
      if (in.gcount() == static_cast<std::streamsize>(stored.size() * sizeof(float))) {
        std::copy(stored.begin(), stored.end(), grid_.begin());
        from_cache_ = true;
        return;
      }
    }
  }
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) grid_[static_cast<std::size_t>(j) * nx + i] = static_cast<float>(field.distance_to_marking({x0 + i * cell, y0 + j * cell}));
  if (!file.empty() && !cache::unwritable()) {
    std::string out = header.str();
    const std::vector<float> stored(grid_.begin(), grid_.end());
    out.append(reinterpret_cast<const char*>(stored.data()), stored.size() * sizeof(float));
    try {
      write_file_atomic(file, out);
    } catch (const std::exception& e) {
      // A full or read-only cache only costs the rebuild next time; said once.
      cache::report_unwritable(e.what());
    }
  }
}

FieldMap::Sample FieldMap::Table::off_table(Table t, double fx, double fy, bool gradient) {
  // Just inside the last row / column, so the cell (i, i + 1) exists (1e-6 cells = 50 nm). Written so
  // that NaN lands on cell (0, 0) (std::clamp passes NaN through, which then indexed far outside the
  // table: a point at -1e308 m made -inf cells, a NaN gradient, a NaN pose and a crash). For every
  // other value it is std::clamp.
  const double cx = fx > 0.0 ? std::min(fx, t.last_x - 0.000001) : 0.0, cy = fy > 0.0 ? std::min(fy, t.last_y - 0.000001) : 0.0;
  Sample s = gradient ? t.interpolate<true>(cx, cy) : t.interpolate<false>(cx, cy);
  const double dx = fx - cx, dy = fy - cy;  // cells
  // Cells: points read from a recording lie within 50 m (docs/recording.md), so no overflow here.
  const double out = std::sqrt(dx * dx + dy * dy);
  if (out > 0) {
    s.d += out * t.cell;  // off the table: farther from everything
    if (gradient) {
      s.gx = dx / out * t.cell;
      s.gy = dy / out * t.cell;
    }
  }
  return s;
}

}  // namespace omniloc
