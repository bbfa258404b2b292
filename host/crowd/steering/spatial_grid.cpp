#include "steering/spatial_grid.hpp"

#include <algorithm>
#include <cmath>

namespace mmvk::crowd {

namespace {
// Bounds the cell count when a few points stray far away: past this many
// cells per side, cells grow instead (queries stay correct, a bit slower).
constexpr int kMaxCellsPerSide = 1024;
}  // namespace

int SpatialGrid::cell_x(float x) const {
  return std::clamp(int(std::floor((x - min_x_) * inv_cell_)), 0, cells_x_ - 1);
}

int SpatialGrid::cell_z(float z) const {
  return std::clamp(int(std::floor((z - min_z_) * inv_cell_)), 0, cells_z_ - 1);
}

void SpatialGrid::build(std::span<const glm::vec3> points, float cell_size) {
  const std::size_t n = points.size();
  float max_x = 0.0f, max_z = 0.0f;
  min_x_ = min_z_ = 0.0f;
  if (n > 0) {
    min_x_ = max_x = points[0].x, min_z_ = max_z = points[0].z;
    for (const glm::vec3& p : points) {
      min_x_ = std::min(min_x_, p.x), max_x = std::max(max_x, p.x);
      min_z_ = std::min(min_z_, p.z), max_z = std::max(max_z, p.z);
    }
  }
  const float extent = std::max(max_x - min_x_, max_z - min_z_);
  cell_size = std::max(cell_size, extent / float(kMaxCellsPerSide - 1));
  inv_cell_ = 1.0f / cell_size;
  cells_x_ = int((max_x - min_x_) * inv_cell_) + 1;
  cells_z_ = int((max_z - min_z_) * inv_cell_) + 1;

  const std::size_t cells = std::size_t(cells_x_) * std::size_t(cells_z_);
  start_.assign(cells + 1, 0);
  cell_of_.resize(n);
  order_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t cell = std::uint32_t(cell_z(points[i].z) * cells_x_ + cell_x(points[i].x));
    cell_of_[i] = cell;
    ++start_[cell + 1];
  }
  for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  // Stable fill: points keep index order inside a cell, so neighbour sums are
  // deterministic (the same on every run and backend).
  fill_.assign(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < n; ++i) order_[fill_[cell_of_[i]]++] = std::uint32_t(i);
}

}  // namespace mmvk::crowd
