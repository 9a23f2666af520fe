#include "mm/offline/body.hpp"
#include "mm/runtime/finite.hpp"
#include "mm/runtime/float_to_integer.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace mm {
namespace {

std::string number(double v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// A tapered capsule with everything that does not depend on the query point computed once.
// In the plane through the axis, with x the distance from the axis and y the coordinate along
// it from `a`, the side line touches both end circles; `normal` is its outward unit normal
// (cos, sin) and `along` = (-sin, cos) runs from the tangent point at `a` to the one at `b`.
struct Capsule {
  glm::vec3 a{0.0f};
  glm::vec3 axis{0.0f, 1.0f, 0.0f};  // unit, a -> b
  float length = 0.0f;
  float ra = 0.0f, rb = 0.0f;
  float sin_side = 0.0f, cos_side = 1.0f;
  bool sphere = false;  // zero length, or one end sphere holds the other
  // A sphere holding the capsule: distance() is at least |p - centre| - bound.
  glm::vec3 centre{0.0f};
  float bound = 0.0f;
};

Capsule prepare(const BoneSegment& s) {
  Capsule c;
  c.a = s.head;
  c.ra = s.head_radius;
  c.rb = s.tail_radius;
  const glm::vec3 d = s.tail - s.head;
  c.length = glm::length(d);
  c.centre = 0.5f * (s.head + s.tail);
  c.bound = 0.5f * c.length + std::max(c.ra, c.rb);
  if (!(c.length > std::abs(c.ra - c.rb)) || !(c.length > 1e-7f)) {
    // The larger sphere contains the smaller one (or both coincide): the hull is that sphere.
    c.sphere = true;
    if (c.rb > c.ra) {
      c.a = s.tail;
      c.ra = c.rb;
    }
    return c;
  }
  c.axis = d / c.length;
  c.sin_side = (c.ra - c.rb) / c.length;
  c.cos_side = std::sqrt(std::max(0.0f, 1.0f - c.sin_side * c.sin_side));
  return c;
}

float distance(const Capsule& c, const glm::vec3& p) {
  const glm::vec3 pa = p - c.a;
  if (c.sphere) return glm::length(pa) - c.ra;
  const float y = glm::dot(pa, c.axis);
  const float x = glm::length(pa - y * c.axis);
  // Which feature is closest: the circle at a, the side line, or the circle at b.
  const float w = -x * c.sin_side + y * c.cos_side;
  if (w < 0.0f) return std::sqrt(x * x + y * y) - c.ra;
  if (w > c.length * c.cos_side) {
    const float yb = y - c.length;
    return std::sqrt(x * x + yb * yb) - c.rb;
  }
  return x * c.cos_side + y * c.sin_side - c.ra;
}

// Polynomial smooth minimum: equal to min(a, b) when they differ by more than k, and below it
// by up to k / 4 where they are equal, with a continuous derivative throughout.
float smooth_min(float a, float b, float k) {
  if (!(k > 0.0f)) return std::min(a, b);
  const float h = std::max(k - std::abs(a - b), 0.0f) / k;
  return std::min(a, b) - h * h * k * 0.25f;
}

// The smooth union folded in segment order. A capsule's signed distance is at least
// |p - centre| - bound, inside it too; where that is `blend` or more above the union so far, the
// capsule cannot change it (smooth_min returns its first argument then), so its distance is not
// computed. The field is the same (the shipped body's file is byte-identical), several times
// faster: most capsules are far from most grid points.
float union_distance(std::span<const Capsule> capsules, float blend, const glm::vec3& p) {
  float d = distance(capsules[0], p);
  for (size_t i = 1; i < capsules.size(); ++i) {
    const Capsule& c = capsules[i];
    const float reach = d + std::max(blend, 0.0f) + c.bound;
    const glm::vec3 off = p - c.centre;
    if (reach <= 0.0f || glm::dot(off, off) >= reach * reach) continue;
    d = smooth_min(d, distance(c, p), blend);
  }
  return d;
}

glm::vec3 union_gradient(std::span<const Capsule> capsules, float blend, const glm::vec3& p,
                         float h) {
  glm::vec3 g;
  for (int axis = 0; axis < 3; ++axis) {
    glm::vec3 step(0.0f);
    step[axis] = h;
    g[axis] = union_distance(capsules, blend, p + step) - union_distance(capsules, blend, p - step);
  }
  return g / (2.0f * h);
}

// ---------------------------------------------------------------------------------------------
// Validation

Status validate_input(std::span<const BoneSegment> segments, const BodyMeshOptions& options) {
  if (!(options.voxel_size > 0.0f) || !std::isfinite(options.voxel_size)) {
    return Error{"body mesh: voxel size must be a positive finite number of metres, got " +
                 number(options.voxel_size)};
  }
  if (!(options.blend_radius >= 0.0f) || !std::isfinite(options.blend_radius)) {
    return Error{"body mesh: blend radius must be a finite number of metres >= 0, got " +
                 number(options.blend_radius)};
  }
  if (segments.empty()) return Error{"body mesh: no bone segments to build a body around"};
  for (size_t i = 0; i < segments.size(); ++i) {
    const BoneSegment& s = segments[i];
    const std::string where =
        "body mesh: segment " + std::to_string(i) + " (joint " + std::to_string(s.joint) + ")";
    if (!finite(s.head) || !finite(s.tail)) return Error{where + ": an end point is not finite"};
    for (const auto& [radius, end] :
         {std::pair{s.head_radius, "head"}, std::pair{s.tail_radius, "tail"}}) {
      if (!(radius > 0.0f) || !std::isfinite(radius)) {
        return Error{where + ": " + end +
                     " radius must be a positive finite number of metres, got " + number(radius)};
      }
    }
  }
  return Status::success();
}

// ---------------------------------------------------------------------------------------------
// The sampling grid

struct Grid {
  glm::vec3 origin{0.0f};  // position of point (0, 0, 0)
  float voxel = 0.0f;
  glm::ivec3 points{0};  // sample points per axis
  std::vector<float> field;

  size_t index(int i, int j, int k) const {
    return static_cast<size_t>(i) +
           static_cast<size_t>(points.x) *
               (static_cast<size_t>(j) + static_cast<size_t>(points.y) * k);
  }
  glm::vec3 position(int i, int j, int k) const {
    return origin +
           voxel * glm::vec3(static_cast<float>(i), static_cast<float>(j), static_cast<float>(k));
  }
  bool inside(int i, int j, int k) const { return field[index(i, j, k)] < 0.0f; }
};

// The grid around every capsule, with two empty voxels beyond the largest the smooth union can
// grow, so every grid point on the border lies outside the surface.
Result<Grid> make_grid(std::span<const BoneSegment> segments, const BodyMeshOptions& options) {
  glm::vec3 lo(std::numeric_limits<float>::max());
  glm::vec3 hi(-std::numeric_limits<float>::max());
  for (const BoneSegment& s : segments) {
    lo = glm::min(lo, glm::min(s.head - s.head_radius, s.tail - s.tail_radius));
    hi = glm::max(hi, glm::max(s.head + s.head_radius, s.tail + s.tail_radius));
  }
  const float pad = 0.25f * options.blend_radius + 2.0f * options.voxel_size;
  lo -= pad;
  hi += pad;
  Grid grid;
  grid.voxel = options.voxel_size;
  grid.origin = lo;
  double total = 1.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double n = std::ceil(static_cast<double>(hi[axis] - lo[axis]) / options.voxel_size) + 1.0;
    total *= n;
    grid.points[axis] = clamped_integer<int>(std::min(n, 2.0e9));
  }
  if (!(total <= static_cast<double>(options.max_grid_points))) {
    return Error{"body mesh: a grid of " + std::to_string(grid.points.x) + " x " +
                 std::to_string(grid.points.y) + " x " + std::to_string(grid.points.z) +
                 " points at voxel size " + number(options.voxel_size) +
                 " m exceeds the limit of " + std::to_string(options.max_grid_points) +
                 " points; use a larger voxel size"};
  }
  return grid;
}

void sample_field(Grid& grid, std::span<const Capsule> capsules, float blend) {
  grid.field.resize(static_cast<size_t>(grid.points.x) * grid.points.y * grid.points.z);
  for (int k = 0; k < grid.points.z; ++k) {
    for (int j = 0; j < grid.points.y; ++j) {
      for (int i = 0; i < grid.points.x; ++i) {
        grid.field[grid.index(i, j, k)] = union_distance(capsules, blend, grid.position(i, j, k));
      }
    }
  }
}

// A grid face whose corners alternate inside/outside around it (the surface grazing the face,
// cutting it twice) would make the edge between its two cells shared by four quads. Moving the
// corner nearest the surface across it, to just on the other side, leaves two crossings; a
// flip can make a neighbouring face ambiguous, so passes repeat until none is left (bounded,
// in case flips chase each other). The vertices are projected onto the true surface later,
// so the shape does not change, only which cells it is taken to pass through.
void resolve_ambiguous_faces(Grid& grid) {
  const glm::ivec3 n = grid.points;
  for (int pass = 0; pass < 16; ++pass) {
    int flips = 0;
    for (int axis = 0; axis < 3; ++axis) {
      glm::ivec3 eu(0), ev(0);
      eu[(axis + 1) % 3] = 1;
      ev[(axis + 2) % 3] = 1;
      const glm::ivec3 end = n - eu - ev;
      for (int k = 0; k < end.z; ++k) {
        for (int j = 0; j < end.y; ++j) {
          for (int i = 0; i < end.x; ++i) {
            const glm::ivec3 p(i, j, k);
            const std::array<size_t, 4> c = {
                grid.index(p.x, p.y, p.z), grid.index(p.x + eu.x, p.y + eu.y, p.z + eu.z),
                grid.index(p.x + eu.x + ev.x, p.y + eu.y + ev.y, p.z + eu.z + ev.z),
                grid.index(p.x + ev.x, p.y + ev.y, p.z + ev.z)};
            std::array<float, 4> f;
            for (size_t q = 0; q < 4; ++q) f[q] = grid.field[c[q]];
            const bool a = f[0] < 0.0f, b = f[1] < 0.0f;
            if (a == b || (f[2] < 0.0f) != a || (f[3] < 0.0f) != b) continue;
            size_t nearest = 0;
            for (size_t q = 1; q < 4; ++q) {
              if (std::abs(f[q]) < std::abs(f[nearest])) nearest = q;
            }
            float& value = grid.field[c[nearest]];
            value = value < 0.0f ? 0.0f : -1e-6f * grid.voxel;
            ++flips;
          }
        }
      }
    }
    if (flips == 0) return;
  }
}

// ---------------------------------------------------------------------------------------------
// Surface nets

constexpr std::array<std::array<int, 2>, 12> kCellEdges = {{{0, 1},
                                                            {2, 3},
                                                            {4, 5},
                                                            {6, 7},
                                                            {0, 2},
                                                            {1, 3},
                                                            {4, 6},
                                                            {5, 7},
                                                            {0, 4},
                                                            {1, 5},
                                                            {2, 6},
                                                            {3, 7}}};

glm::ivec3 corner_offset(int corner) {
  return {corner & 1, (corner >> 1) & 1, (corner >> 2) & 1};
}

// The cell's vertex: the mean of the points where the surface crosses its edges (linear
// interpolation of the sampled distances), moved onto the surface by Newton steps along the
// gradient; a step never takes it more than a voxel from where it started.
glm::vec3 cell_vertex(const Grid& grid, std::span<const Capsule> capsules, float blend,
                      const glm::ivec3& cell) {
  std::array<float, 8> f;
  for (int c = 0; c < 8; ++c) {
    const glm::ivec3 p = cell + corner_offset(c);
    f[static_cast<size_t>(c)] = grid.field[grid.index(p.x, p.y, p.z)];
  }
  glm::vec3 sum(0.0f);
  int crossings = 0;
  for (const auto& [c0, c1] : kCellEdges) {
    const float f0 = f[static_cast<size_t>(c0)], f1 = f[static_cast<size_t>(c1)];
    if ((f0 < 0.0f) == (f1 < 0.0f)) continue;
    const float t = f0 / (f0 - f1);
    sum += glm::mix(glm::vec3(corner_offset(c0)), glm::vec3(corner_offset(c1)), t);
    ++crossings;
  }
  const glm::vec3 start =
      grid.position(cell.x, cell.y, cell.z) + grid.voxel * sum / static_cast<float>(crossings);
  glm::vec3 p = start;
  for (int iteration = 0; iteration < 3; ++iteration) {
    const float d = union_distance(capsules, blend, p);
    const glm::vec3 g = union_gradient(capsules, blend, p, 0.05f * grid.voxel);
    const float g2 = glm::dot(g, g);
    if (!(g2 > 1e-12f)) break;
    glm::vec3 next = p - d * g / g2;
    const glm::vec3 moved = next - start;
    const float len = glm::length(moved);
    if (len > grid.voxel) next = start + moved * (grid.voxel / len);
    p = next;
  }
  return p;
}

struct NetVertices {
  std::vector<int32_t> of_cell;  // vertex index per cell, -1 where the surface does not pass
  glm::ivec3 cells{0};
  size_t index(const glm::ivec3& c) const {
    return static_cast<size_t>(c.x) +
           static_cast<size_t>(cells.x) *
               (static_cast<size_t>(c.y) + static_cast<size_t>(cells.y) * c.z);
  }
};

NetVertices place_vertices(const Grid& grid, std::span<const Capsule> capsules, float blend,
                           TriangleMesh& mesh) {
  NetVertices net;
  net.cells = grid.points - 1;
  net.of_cell.assign(static_cast<size_t>(net.cells.x) * net.cells.y * net.cells.z, -1);
  for (int k = 0; k < net.cells.z; ++k) {
    for (int j = 0; j < net.cells.y; ++j) {
      for (int i = 0; i < net.cells.x; ++i) {
        int inside = 0;
        for (int c = 0; c < 8; ++c) {
          const glm::ivec3 p = glm::ivec3(i, j, k) + corner_offset(c);
          inside += grid.inside(p.x, p.y, p.z) ? 1 : 0;
        }
        if (inside == 0 || inside == 8) continue;
        net.of_cell[net.index({i, j, k})] = static_cast<int32_t>(mesh.positions.size());
        mesh.positions.push_back(cell_vertex(grid, capsules, blend, {i, j, k}));
      }
    }
  }
  return net;
}

// One quad per crossed grid edge, joining the four cells around the edge, wound so that its
// normal points from the inside end of the edge to the outside end.
void emit_quad(const NetVertices& net, const glm::ivec3& base, int axis, bool inside_first,
               TriangleMesh& mesh) {
  glm::ivec3 eu(0), ev(0);
  eu[(axis + 1) % 3] = 1;
  ev[(axis + 2) % 3] = 1;
  // Counter-clockwise about +axis: (u-, v-), (u+, v-), (u+, v+), (u-, v+).
  std::array<uint32_t, 4> q = {static_cast<uint32_t>(net.of_cell[net.index(base - eu - ev)]),
                               static_cast<uint32_t>(net.of_cell[net.index(base - ev)]),
                               static_cast<uint32_t>(net.of_cell[net.index(base)]),
                               static_cast<uint32_t>(net.of_cell[net.index(base - eu)])};
  if (!inside_first) std::swap(q[1], q[3]);
  const auto& pos = mesh.positions;
  const float d02 = glm::distance(pos[q[0]], pos[q[2]]);
  const float d13 = glm::distance(pos[q[1]], pos[q[3]]);
  if (d02 <= d13) {
    mesh.indices.insert(mesh.indices.end(), {q[0], q[1], q[2], q[0], q[2], q[3]});
  } else {
    mesh.indices.insert(mesh.indices.end(), {q[0], q[1], q[3], q[1], q[2], q[3]});
  }
}

void connect_quads(const Grid& grid, const NetVertices& net, TriangleMesh& mesh) {
  // Border points lie outside, so an edge whose ends differ is never on the border and its four
  // cells all exist.
  for (int k = 1; k + 1 < grid.points.z; ++k) {
    for (int j = 1; j + 1 < grid.points.y; ++j) {
      for (int i = 1; i + 1 < grid.points.x; ++i) {
        const bool here = grid.inside(i, j, k);
        const std::array<bool, 3> next = {grid.inside(i + 1, j, k), grid.inside(i, j + 1, k),
                                          grid.inside(i, j, k + 1)};
        for (int axis = 0; axis < 3; ++axis) {
          if (here != next[static_cast<size_t>(axis)]) emit_quad(net, {i, j, k}, axis, here, mesh);
        }
      }
    }
  }
}

void compute_normals(std::span<const Capsule> capsules, float blend, float voxel,
                     TriangleMesh& mesh) {
  mesh.normals.resize(mesh.positions.size());
  for (size_t v = 0; v < mesh.positions.size(); ++v) {
    const glm::vec3 g = union_gradient(capsules, blend, mesh.positions[v], 0.05f * voxel);
    const float len = glm::length(g);
    mesh.normals[v] = len > 1e-12f ? g / len : glm::vec3(0.0f, 1.0f, 0.0f);
  }
}

std::vector<Capsule> prepare_all(std::span<const BoneSegment> segments) {
  std::vector<Capsule> capsules;
  capsules.reserve(segments.size());
  for (const BoneSegment& s : segments) capsules.push_back(prepare(s));
  return capsules;
}

}  // namespace

float tapered_capsule_distance(const BoneSegment& segment, const glm::vec3& point) {
  return distance(prepare(segment), point);
}

float body_signed_distance(std::span<const BoneSegment> segments, float blend_radius,
                           const glm::vec3& point) {
  const std::vector<Capsule> capsules = prepare_all(segments);
  return union_distance(capsules, blend_radius, point);
}

Result<TriangleMesh> generate_body_mesh(std::span<const BoneSegment> segments,
                                        const BodyMeshOptions& options) {
  if (Status s = validate_input(segments, options); !s) return Error{s.message()};
  Result<Grid> grid = make_grid(segments, options);
  if (!grid) return grid.error();
  const std::vector<Capsule> capsules = prepare_all(segments);
  const float blend = options.blend_radius;
  sample_field(*grid, capsules, blend);
  resolve_ambiguous_faces(*grid);

  TriangleMesh mesh;
  const NetVertices net = place_vertices(*grid, capsules, blend, mesh);
  connect_quads(*grid, net, mesh);
  compute_normals(capsules, blend, grid->voxel, mesh);
  return mesh;
}

}  // namespace mm
