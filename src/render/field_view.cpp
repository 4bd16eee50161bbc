#include "render/field_view.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "core/error.hpp"

namespace panoptes::render {
namespace {
std::string str(const Index3& v) {
  return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")";
}
}  // namespace

double GridGeometry::voxel() const { return std::min({spacing.x, spacing.y, spacing.z}); }

void GridGeometry::validate() const {
  for (int a = 0; a < 3; ++a) {
    if (dims[a] < 2) throw Error("grid: dims " + str(dims) + "; expected at least 2 points per axis");
    if (!(std::isfinite(spacing[a]) && spacing[a] > 0))
      throw Error("grid: spacing component " + std::to_string(spacing[a]) + "; expected a finite value > 0");
    if (!std::isfinite(origin[a])) throw Error("grid: origin is not finite");
  }
}

Brick Brick::slab(const GridGeometry& g, int axis, int parts, int index) {
  if (axis < 0 || axis > 2) throw Error("brick: axis " + std::to_string(axis) + "; expected 0, 1 or 2");
  Brick b = whole(g);
  const int n = b.hi[axis];
  if (parts < 1 || parts > n || index < 0 || index >= parts)
    throw Error("brick: part " + std::to_string(index) + " of " + std::to_string(parts) + " along an axis of " +
                std::to_string(n) + " cells; expected 0 <= index < parts <= cells");
  b.lo[axis] = int(std::int64_t(n) * index / parts);
  b.hi[axis] = int(std::int64_t(n) * (index + 1) / parts);
  return b;
}

PointRange required_points(const GridGeometry& g, const Brick& b) {
  PointRange r;
  for (int a = 0; a < 3; ++a) {
    r.lo[a] = std::max(0, b.lo[a] - 2);
    r.hi[a] = std::min(g.dims[a], b.hi[a] + 3);
  }
  return r;
}

FieldView FieldView::whole(const GridGeometry& g, const float* data) {
  FieldView v;
  v.grid = g;
  v.brick = Brick::whole(g);
  v.points = {{0, 0, 0}, g.dims};
  v.data = data;
  v.stride = {1, g.dims[0], std::int64_t(g.dims[0]) * g.dims[1]};
  return v;
}

FieldView FieldView::of_brick(const GridGeometry& g, const Brick& b, const PointRange& points, const float* data) {
  FieldView v;
  v.grid = g;
  v.brick = b;
  v.points = points;
  v.data = data;
  const std::int64_t nx = points.hi[0] - points.lo[0], ny = points.hi[1] - points.lo[1];
  v.stride = {1, nx, nx * ny};
  return v;
}

FieldView FieldView::subview(const Brick& b) const {
  FieldView v = *this;
  v.brick = b;
  v.points = required_points(grid, b);
  if (!points.contains(v.points))
    throw Error("field view: brick " + str(b.lo) + "-" + str(b.hi) + " needs points outside the view's data");
  v.data = data + std::int64_t(v.points.lo[0] - points.lo[0]) * stride[0] +
           std::int64_t(v.points.lo[1] - points.lo[1]) * stride[1] +
           std::int64_t(v.points.lo[2] - points.lo[2]) * stride[2];
  return v;
}

void FieldView::validate() const {
  grid.validate();
  if (!data) throw Error("field view: null data pointer");
  for (int a = 0; a < 3; ++a)
    if (brick.lo[a] < 0 || brick.hi[a] > grid.dims[a] - 1 || brick.lo[a] >= brick.hi[a])
      throw Error("field view: brick cells " + str(brick.lo) + "-" + str(brick.hi) + " on a grid of " +
                  str(grid.dims) + " points; expected 0 <= lo < hi <= dims-1");
  const PointRange need = required_points(grid, brick);
  if (!points.contains(need))
    throw Error("field view: data covers points " + str(points.lo) + "-" + str(points.hi) + " but brick " +
                str(brick.lo) + "-" + str(brick.hi) + " needs points " + str(need.lo) + "-" + str(need.hi) +
                " (two ghost layers below, the shared point and two more above)");
}

}  // namespace panoptes::render
