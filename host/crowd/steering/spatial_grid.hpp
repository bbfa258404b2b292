// A uniform grid over the ground plane, rebuilt every tick by counting sort,
// so that neighbour queries cost O(neighbours) instead of O(N).
// No allocation after the first build with a given agent count and bounds.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

namespace mmvk::crowd {

class SpatialGrid {
 public:
  // Over the points' (x, z) (y ignored); cells are `cell_size` metres wide;
  // points outside [min, min + extent) are clamped into the border cells,
  // which stays correct (only slower).
  void build(std::span<const glm::vec3> points, float cell_size);

  // Calls visit(j) for every point j in the 3x3 cells around (x, z); with
  // cell_size >= the query radius that covers every point within it.
  template <class Visit>
  void for_each_near(float x, float z, Visit&& visit) const {
    const int cx = cell_x(x), cz = cell_z(z);
    for (int gz = cz - 1; gz <= cz + 1; ++gz) {
      if (gz < 0 || gz >= cells_z_) continue;
      for (int gx = cx - 1; gx <= cx + 1; ++gx) {
        if (gx < 0 || gx >= cells_x_) continue;
        const std::size_t cell = std::size_t(gz) * std::size_t(cells_x_) + std::size_t(gx);
        for (std::uint32_t k = start_[cell]; k < start_[cell + 1]; ++k) visit(order_[k]);
      }
    }
  }

  int cells_x() const { return cells_x_; }
  int cells_z() const { return cells_z_; }

 private:
  int cell_x(float x) const;
  int cell_z(float z) const;

  float min_x_ = 0.0f, min_z_ = 0.0f, inv_cell_ = 1.0f;
  int cells_x_ = 0, cells_z_ = 0;
  std::vector<std::uint32_t> cell_of_;  // [points]
  std::vector<std::uint32_t> start_;    // [cells + 1], prefix sums
  std::vector<std::uint32_t> order_;    // [points], point ids sorted by cell
  std::vector<std::uint32_t> fill_;     // [cells], write cursors of the counting sort
};

}  // namespace mmvk::crowd
