#pragma once
// A body surface generated around bone segments: one closed triangle mesh that a character can
// be skinned with when no artist-made mesh exists.
//
// The shape is the smooth union of the segments' tapered capsules ("round cones": the convex
// hull of a sphere at each end). Each capsule has an exact signed distance; the union takes
// the polynomial smooth minimum of them, so where two capsules meet the surface is filleted
// over about `blend_radius` instead of creasing. (The smooth minimum of more than two is folded
// left to right in segment order, which keeps the result deterministic.)
//
// The surface is polygonized with naive surface nets on a regular grid of `voxel_size`: the
// signed distance is sampled at the grid points, every cell the surface crosses gets one
// vertex (the mean of its edge crossings, then projected onto the surface along the distance
// gradient), and every grid edge the surface crosses gets a quad joining the four cells around
// it, split into two triangles along its shorter diagonal. Surface nets rather than marching
// cubes: no 256-case tables, about half the vertices for the same grid, and no sliver
// triangles, whose very short edges would dominate the graph Laplacian (1 / length^2 per edge)
// of the heat-diffusion weights (bone_weights.hpp).
// Because the grid extends beyond the surface on every side, every crossed edge has its four
// cells and the mesh is closed. A grid face whose four corners alternate inside/outside (the
// surface grazing it) would make one edge shared by four triangles; such faces are resolved
// before meshing by moving their corner nearest the surface to its other side, so every edge
// is shared by exactly two triangles. Features thinner than a voxel may still vanish or break:
// keep voxels smaller than the thinnest capsule.
//
// Normals are the normalized gradient of the signed distance (central differences), pointing
// out; triangles wind counter-clockwise seen from outside. Units: metres, like everything else.
// Deterministic: single-threaded, fixed evaluation order.

#include <span>

#include "mm/runtime/mesh.hpp"
#include "mm/runtime/result.hpp"

namespace mm {

struct BodyMeshOptions {
  // Edge length of the sampling grid's cells (metres, finite, > 0). One vertex per crossed
  // cell: a 1.7 m human takes roughly (surface area / voxel_size^2) vertices.
  float voxel_size = 0.012f;
  // Width of the fillet where capsules meet (metres, finite, >= 0; 0 is a plain union). The
  // smooth union grows the shape by at most blend_radius / 4 where capsules overlap.
  float blend_radius = 0.03f;
  // The grid may hold at most this many sample points; a finer grid is refused rather than
  // allocated.
  size_t max_grid_points = 64u * 1024u * 1024u;
};

// The signed distance (metres, negative inside) of one tapered capsule at `point`. A segment
// of zero length, or one whose larger end sphere contains the other, is that sphere.
float tapered_capsule_distance(const BoneSegment& segment, const glm::vec3& point);

// The smooth union of every segment's tapered capsule at `point` (see the top of this file).
// `segments` must not be empty.
float body_signed_distance(std::span<const BoneSegment> segments, float blend_radius,
                           const glm::vec3& point);

// Polygonizes the smooth union of the segments' capsules into one closed mesh with outward
// normals. Fails with a message on no segments, a non-finite point, a radius that is not
// finite and > 0, bad options, or a grid larger than max_grid_points. Joint indices are not
// read here (weights come later, from compute_bone_weights).
Result<TriangleMesh> generate_body_mesh(std::span<const BoneSegment> segments,
                                        const BodyMeshOptions& options = {});

}  // namespace mm
