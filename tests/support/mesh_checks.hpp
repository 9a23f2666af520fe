#pragma once
// Topology and volume checks of triangle meshes shared by the body tests (header-only: the
// support library does not link the runtime).

#include <algorithm>
#include <cstdint>
#include <map>
#include <numeric>
#include <utility>
#include <vector>

#include <glm/glm.hpp>

#include "mm/runtime/mesh.hpp"

namespace mm::test {

// How many triangles use each undirected edge, and whether every directed edge appears once
// (two triangles sharing an edge traverse it in opposite directions when their windings agree).
struct EdgeReport {
  size_t edges = 0;
  size_t edges_not_shared_by_two = 0;  // boundary or non-manifold edges
  size_t directed_edges_repeated = 0;  // neighbours with opposite windings
};

inline EdgeReport edge_report(const TriangleMesh& mesh) {
  std::map<std::pair<uint32_t, uint32_t>, int> undirected;
  std::map<std::pair<uint32_t, uint32_t>, int> directed;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      const uint32_t a = mesh.indices[t + static_cast<size_t>(e)];
      const uint32_t b = mesh.indices[t + static_cast<size_t>((e + 1) % 3)];
      ++undirected[{std::min(a, b), std::max(a, b)}];
      ++directed[{a, b}];
    }
  }
  EdgeReport report;
  report.edges = undirected.size();
  for (const auto& [edge, count] : undirected) report.edges_not_shared_by_two += count != 2;
  for (const auto& [edge, count] : directed) report.directed_edges_repeated += count != 1;
  return report;
}

// Sum over triangles of the signed volume of the tetrahedron they make with the origin: the
// enclosed volume, positive when triangles wind counter-clockwise seen from outside.
inline double signed_volume(const TriangleMesh& mesh) {
  double volume = 0.0;
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    const glm::dvec3 a(mesh.positions[mesh.indices[t]]);
    const glm::dvec3 b(mesh.positions[mesh.indices[t + 1]]);
    const glm::dvec3 c(mesh.positions[mesh.indices[t + 2]]);
    volume += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return volume;
}

// Connected components of the triangles' vertex graph (vertices no triangle uses count as
// components of their own).
inline int connected_components(const TriangleMesh& mesh) {
  std::vector<uint32_t> root(mesh.positions.size());
  std::iota(root.begin(), root.end(), 0u);
  auto find = [&](uint32_t v) {
    while (root[v] != v) v = root[v] = root[root[v]];
    return v;
  };
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    for (int e = 1; e < 3; ++e) {
      root[find(mesh.indices[t + static_cast<size_t>(e)])] = find(mesh.indices[t]);
    }
  }
  int count = 0;
  for (uint32_t v = 0; v < root.size(); ++v) count += find(v) == v;
  return count;
}

}  // namespace mm::test
