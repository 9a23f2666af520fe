#include "mm/offline/preprocess.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>

#include "mm/runtime/assert.hpp"
#include "mm/runtime/float_to_integer.hpp"
#include "mm/runtime/interpolation.hpp"
#include "mm/runtime/pose.hpp"

namespace mm {

namespace {

// The reflection of a global transform across the YZ plane (x -> -x). The rotation R becomes
// S R S with S = diag(-1, 1, 1): the axis (x, y, z) turns into (-x, y, z) and the angle changes
// sign, which as a quaternion is (w, x, -y, -z).
Transform reflect_x(const Transform& t) {
  Transform out = t;
  out.translation.x = -t.translation.x;
  out.rotation = glm::quat(t.rotation.w, t.rotation.x, -t.rotation.y, -t.rotation.z);
  return out;
}

// ---- Mirroring: the per-joint correction of the reflected rotations -------------------------
//
// A mirrored joint's global rotation is M R N, with M the world reflection x -> -x and N an
// improper matrix in the joint's own frame (det -1) that says how the partner's local axes
// map onto the joint's. The correction mirror_clip applies is C = M N (a rotation). The
// matrices here are in double: they are constants of the skeleton and mirroring twice must
// give the clip back to float precision.

using Mat3 = glm::dmat3;
using Vec3 = glm::dvec3;

const Mat3 kReflectX(-1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);

// Eigenvalues and eigenvectors (the columns of `vectors`) of a symmetric matrix, by cyclic
// Jacobi rotations; a[i][j] is row i, column j.
template <size_t L>
using Square = std::array<std::array<double, L>, L>;

template <size_t L>
void symmetric_eigen(Square<L> a, Square<L>& vectors, std::array<double, L>& values) {
  for (size_t i = 0; i < L; ++i) {
    for (size_t k = 0; k < L; ++k) vectors[i][k] = i == k ? 1.0 : 0.0;
  }
  for (int sweep = 0; sweep < 64; ++sweep) {
    double off = 0.0;
    for (size_t p = 0; p < L; ++p) {
      for (size_t q = p + 1; q < L; ++q) off += a[p][q] * a[p][q];
    }
    if (off < 1e-30) break;
    for (size_t p = 0; p < L; ++p) {
      for (size_t q = p + 1; q < L; ++q) {
        if (std::abs(a[p][q]) < 1e-300) continue;
        const double theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
        const double t =
            (theta >= 0.0 ? 1.0 : -1.0) / (std::abs(theta) + std::sqrt(theta * theta + 1.0));
        const double c = 1.0 / std::sqrt(t * t + 1.0), s = t * c;
        for (size_t k = 0; k < L; ++k) {  // A J
          const double kp = a[k][p], kq = a[k][q];
          a[k][p] = c * kp - s * kq;
          a[k][q] = s * kp + c * kq;
        }
        for (size_t k = 0; k < L; ++k) {  // J^T (A J)
          const double pk = a[p][k], qk = a[q][k];
          a[p][k] = c * pk - s * qk;
          a[q][k] = s * pk + c * qk;
        }
        for (size_t k = 0; k < L; ++k) {  // V J
          const double kp = vectors[k][p], kq = vectors[k][q];
          vectors[k][p] = c * kp - s * kq;
          vectors[k][q] = s * kp + c * kq;
        }
      }
    }
  }
  for (size_t i = 0; i < L; ++i) values[i] = a[i][i];
}

// The rotation R that best maps each from[i] onto to[i] (least squares), by Horn's method: the
// quaternion is the eigenvector of the largest eigenvalue of a symmetric 4x4 matrix.
Mat3 best_rotation(std::span<const Vec3> from, std::span<const Vec3> to) {
  Mat3 s(0.0);  // s[i][k] = sum from_i * to_k
  for (size_t n = 0; n < from.size(); ++n) {
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 3; ++k) s[i][k] += from[n][i] * to[n][k];
    }
  }
  const double xx = s[0][0], xy = s[0][1], xz = s[0][2], yx = s[1][0], yy = s[1][1];
  const double yz = s[1][2], zx = s[2][0], zy = s[2][1], zz = s[2][2];
  const Square<4> horn = {{{xx + yy + zz, yz - zy, zx - xz, xy - yx},
                           {yz - zy, xx - yy - zz, xy + yx, zx + xz},
                           {zx - xz, xy + yx, -xx + yy - zz, yz + zy},
                           {xy - yx, zx + xz, yz + zy, -xx - yy + zz}}};
  Square<4> vectors;
  std::array<double, 4> values;
  symmetric_eigen(horn, vectors, values);
  const size_t best =
      static_cast<size_t>(std::max_element(values.begin(), values.end()) - values.begin());
  const glm::dquat q(vectors[0][best], vectors[1][best], vectors[2][best], vectors[3][best]);
  return glm::mat3_cast(glm::normalize(q));
}

// The symmetric improper matrix nearest to `n` (a reflection or -I): what a joint that is its
// own partner needs so that mirroring twice is the identity.
Mat3 nearest_involution(const Mat3& n) {
  const Mat3 sym = 0.5 * (n + glm::transpose(n));
  Square<3> a, vectors;
  for (int i = 0; i < 3; ++i) {
    for (int k = 0; k < 3; ++k) a[i][k] = sym[k][i];
  }
  std::array<double, 3> values;
  symmetric_eigen(a, vectors, values);
  Mat3 out(0.0);
  for (int e = 0; e < 3; ++e) {
    const Vec3 v(vectors[0][e], vectors[1][e], vectors[2][e]);
    out += (values[e] < 0.0 ? -1.0 : 1.0) * glm::outerProduct(v, v);
  }
  return out;
}

// The rest offsets of a joint's children paired with those of its partner's matching children
// (child offset -> partner's child offset), longest first; negligible offsets are left out.
struct BonePairs {
  std::vector<Vec3> own, partner;
};

BonePairs bone_pairs(const Skeleton& skeleton, std::span<const int> map, int joint,
                     const std::vector<std::vector<int>>& children) {
  std::vector<std::pair<Vec3, Vec3>> pairs;
  for (const int c : children[joint]) {
    const int mc = map[c];
    if (skeleton.parent(mc) != map[joint]) continue;  // not a mirror image of this bone
    const Vec3 a(skeleton.rest(c).translation), b(skeleton.rest(mc).translation);
    if (glm::length(a) > 1e-6 && glm::length(b) > 1e-6) pairs.emplace_back(a, b);
  }
  std::sort(pairs.begin(), pairs.end(), [](const auto& x, const auto& y) {
    return glm::length(x.first) > glm::length(y.first);
  });
  BonePairs out;
  for (const auto& [a, b] : pairs) {
    out.own.push_back(a);
    out.partner.push_back(b);
  }
  return out;
}

// Whether the bones point in at least two directions (then they fix the whole frame).
bool spans_a_plane(const BonePairs& bones) {
  for (size_t i = 0; i < bones.own.size(); ++i) {
    for (size_t k = i + 1; k < bones.own.size(); ++k) {
      const Vec3 cross = glm::cross(glm::normalize(bones.own[i]), glm::normalize(bones.own[k]));
      if (glm::length(cross) > 0.1) return true;
    }
  }
  return false;
}

// Whether n maps the joint's (longest) bone onto the same side as the partner's.
bool keeps_bone_direction(const Mat3& n, const BonePairs& bones) {
  return bones.own.empty() || glm::dot(n * bones.own[0], bones.partner[0]) > 0.0;
}

// n composed with a half turn about its mirror normal (the axis the reflection negates, made
// perpendicular to the bone): the bone then points the other way while the mirror plane stays.
// This is how a partner whose rest offsets are the negated ones (every axis flipped, as in
// rigs that mirror joint orientations by behaviour) relates to a parent mirrored by a plane.
Mat3 flip_bone(const Mat3& n, const Vec3& bone) {
  const glm::dquat rotation = glm::quat_cast(-n);  // -n is a rotation about the normal
  const Vec3 b = glm::normalize(bone);
  Vec3 normal(rotation.x, rotation.y, rotation.z);
  normal -= glm::dot(normal, b) * b;
  if (glm::length(normal) < 1e-9) {  // no plane: any axis across the bone will do
    normal = glm::cross(b, std::abs(b.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0));
  }
  normal = glm::normalize(normal);
  const Mat3 half_turn = 2.0 * glm::outerProduct(normal, normal) - Mat3(1.0);
  return n * half_turn;
}

// What the corrections are computed from, and the improper maps found so far.
struct RestMirror {
  std::vector<std::vector<int>> children;
  std::vector<Mat3> rest;  // rest local rotations
  std::vector<BonePairs> bones;
  std::vector<Mat3> n;         // per joint: N, its frame -> its partner's, reflected
  std::vector<uint8_t> known;  // N is set
};

RestMirror start_rest_mirror(const Skeleton& skeleton, std::span<const int> map) {
  const int joints = skeleton.joint_count();
  RestMirror m;
  m.children.resize(joints);
  for (int j = 0; j < joints; ++j) {
    if (skeleton.parent(j) >= 0) m.children[skeleton.parent(j)].push_back(j);
  }
  for (int j = 0; j < joints; ++j) {
    m.rest.push_back(glm::mat3_cast(glm::dquat(skeleton.rest(j).rotation)));
    m.bones.push_back(bone_pairs(skeleton, map, j, m.children));
  }
  m.n.assign(joints, Mat3(1.0));
  m.known.assign(joints, 0);
  return m;
}

// Phase 1: a joint whose bones point in several directions is mirrored by the improper map
// that best takes its bones onto its partner's (N = M R, R the rotation taking each bone onto
// the reflection of the partner's).
void fit_branching_joints(RestMirror& m) {
  for (size_t j = 0; j < m.n.size(); ++j) {
    const BonePairs& bones = m.bones[j];
    if (!spans_a_plane(bones)) continue;
    std::vector<Vec3> reflected;
    for (const Vec3& b : bones.partner) reflected.push_back(kReflectX * b);
    m.n[j] = kReflectX * best_rotation(bones.own, reflected);
    m.known[j] = 1;
  }
}

// Phase 2, children first: a joint with one bone takes its child's map carried through the rest
// rotations (a spine segment is oriented like the chest it carries), when that keeps the bone
// on the partner's side.
void carry_up_chains(RestMirror& m, std::span<const int> map) {
  for (int j = static_cast<int>(m.n.size()) - 1; j >= 0; --j) {
    if (m.known[j] || m.children[j].size() != 1 || m.bones[j].own.empty()) continue;
    const int c = m.children[j][0];
    if (!m.known[c]) continue;
    const Mat3 carried = m.rest[map[c]] * m.n[c] * glm::transpose(m.rest[c]);
    if (!keeps_bone_direction(carried, m.bones[j])) continue;
    m.n[j] = carried;
    m.known[j] = 1;
  }
}

// Phase 3, parents first: every other joint takes its parent's map (a root the world's, M)
// carried through the rest rotations, turned half a turn when its bone would point away from
// the partner's.
void carry_down_chains(RestMirror& m, const Skeleton& skeleton, std::span<const int> map) {
  for (size_t j = 0; j < m.n.size(); ++j) {
    if (m.known[j]) continue;
    const int p = skeleton.parent(static_cast<int>(j));
    const Mat3 parent = p < 0 ? kReflectX : m.n[p];
    Mat3 carried = glm::transpose(m.rest[map[j]]) * parent * m.rest[j];
    if (!keeps_bone_direction(carried, m.bones[j])) carried = flip_bone(carried, m.bones[j].own[0]);
    m.n[j] = carried;
    m.known[j] = 1;
  }
}

// Phase 4: mirroring twice turns a joint's rotation R into R N_m(j) N_j, so a joint's map and its
// partner's must be inverses, and the map of a joint that is its own partner an involution. The
// phases above give that up to rounding and to the small left/right differences of a real
// actor's rest offsets; this makes it exact (the later joint of a pair takes the inverse of the
// earlier one's map).
void pair_up(RestMirror& m, std::span<const int> map) {
  for (size_t j = 0; j < m.n.size(); ++j) {
    const size_t partner = static_cast<size_t>(map[j]);
    if (partner == j) {
      m.n[j] = nearest_involution(m.n[j]);
    } else if (j < partner) {
      m.n[partner] = glm::transpose(m.n[j]);
    }
  }
}

// Gaussian-weighted local linear fit of `in` at every frame (window +-3 sigma frames, cut at
// the clip ends). Inside the clip the window is symmetric and this is a plain normalized
// Gaussian filter; where the window is cut the linear term removes the lag a cut filter adds.
void smooth_gaussian_linear(std::span<const glm::vec3> in, float sigma_frames,
                            std::span<glm::vec3> out, std::vector<float>& weights) {
  const int n = static_cast<int>(in.size());
  if (sigma_frames < 0.5f || n < 3) {
    std::copy(in.begin(), in.end(), out.begin());
    return;
  }
  const int radius = std::max(1, clamped_integer<int>(std::ceil(3.0f * sigma_frames)));
  weights.resize(radius + 1);
  for (int k = 0; k <= radius; ++k) {
    weights[k] = std::exp(-0.5f * static_cast<float>(k * k) / (sigma_frames * sigma_frames));
  }
  float full_sum = weights[0];
  for (int k = 1; k <= radius; ++k) full_sum += 2.0f * weights[k];
  for (int f = 0; f < n; ++f) {
    const int lo = std::max(0, f - radius);
    const int hi = std::min(n - 1, f + radius);
    if (lo == f - radius && hi == f + radius) {
      // A whole, symmetric window: the linear term vanishes and this is a Gaussian filter.
      glm::vec3 sum = weights[0] * in[f];
      for (int k = 1; k <= radius; ++k) sum += weights[k] * (in[f - k] + in[f + k]);
      out[f] = sum / full_sum;
      continue;
    }
    double s0 = 0.0, s1 = 0.0, s2 = 0.0;
    glm::dvec3 t0(0.0), t1(0.0);
    for (int i = lo; i <= hi; ++i) {
      const int k = i - f;
      const double w = weights[std::abs(k)];
      s0 += w;
      s1 += w * k;
      s2 += w * k * k;
      t0 += w * glm::dvec3(in[i]);
      t1 += (w * k) * glm::dvec3(in[i]);
    }
    const double det = s0 * s2 - s1 * s1;
    out[f] = std::abs(s1) < 1e-9 || det <= 1e-12 ? glm::vec3(t0 / s0)
                                                 : glm::vec3((s2 * t0 - s1 * t1) / det);
  }
}

// Replaces each run of contact values by the majority of its neighbourhood (width frames,
// odd), so single-frame flickers vanish. Near the clip ends the window is cut; a tie keeps the
// frame's own value.
void majority_filter(std::span<const uint8_t> in, int width, int stride, int offset,
                     std::span<uint8_t> out) {
  const int n = static_cast<int>(in.size());
  const int half = width / 2;
  for (int f = 0; f < n; ++f) {
    const int lo = std::max(0, f - half);
    const int hi = std::min(n - 1, f + half);
    int ones = 0;
    for (int i = lo; i <= hi; ++i) ones += in[i];
    const int total = hi - lo + 1;
    const uint8_t value = 2 * ones > total ? 1 : (2 * ones < total ? 0 : in[f]);
    out[static_cast<size_t>(f) * stride + offset] = value;
  }
}

}  // namespace

std::vector<glm::quat> mirror_corrections(const Skeleton& skeleton,
                                          std::span<const int> joint_map) {
  MM_ASSERT(static_cast<int>(joint_map.size()) == skeleton.joint_count());
  RestMirror m = start_rest_mirror(skeleton, joint_map);
  fit_branching_joints(m);
  carry_up_chains(m, joint_map);
  carry_down_chains(m, skeleton, joint_map);
  pair_up(m, joint_map);
  std::vector<glm::quat> out;
  for (const Mat3& n : m.n) out.push_back(glm::normalize(glm::quat(glm::quat_cast(kReflectX * n))));
  return out;
}

Clip mirror_clip(const Clip& clip, std::span<const int> joint_map) {
  const int joints = clip.joint_count();
  MM_ASSERT(static_cast<int>(joint_map.size()) == joints);
  Clip out;
  out.name = clip.name + "_mirror";
  out.source_path = clip.source_path;
  out.skeleton = clip.skeleton;
  out.frame_time = clip.frame_time;
  out.frame_count = clip.frame_count;
  out.local.resize(clip.local.size());
  const std::vector<int>& parents = clip.skeleton.parents();
  const std::vector<glm::quat> corrections = mirror_corrections(clip.skeleton, joint_map);
  std::vector<Transform> global(joints), mirrored(joints);
  for (int f = 0; f < clip.frame_count; ++f) {
    forward_kinematics(parents, clip.pose(f), global);
    for (int j = 0; j < joints; ++j) {
      mirrored[j] = reflect_x(global[joint_map[j]]);
      mirrored[j].rotation = mirrored[j].rotation * corrections[j];
    }
    std::span<Transform> local = out.pose(f);
    for (int j = 0; j < joints; ++j) {
      const int p = parents[j];
      local[j] = p < 0 ? mirrored[j] : compose(inverse(mirrored[p]), mirrored[j]);
      local[j].rotation = glm::normalize(local[j].rotation);
      local[j].scale = clip.pose(f)[joint_map[j]].scale;
    }
  }
  return out;
}

bool needs_resampling(const Clip& clip, float rate) {
  return std::abs(clip.frame_time * rate - 1.0f) > 1e-3f;
}

Clip resample_clip(const Clip& clip, float rate) {
  Clip out;
  out.name = clip.name;
  out.source_path = clip.source_path;
  out.skeleton = clip.skeleton;
  out.end_sites = clip.end_sites;
  out.frame_time = 1.0f / rate;
  if (!needs_resampling(clip, rate)) {
    out.frame_count = clip.frame_count;
    out.local = clip.local;
    return out;
  }
  const int joints = clip.joint_count();
  const double duration = static_cast<double>(clip.frame_count - 1) * clip.frame_time;
  out.frame_count = clip.frame_count <= 1
                        ? clip.frame_count
                        : clamped_integer<int>(std::floor(duration * rate + 1e-3)) + 1;
  out.local.resize(static_cast<size_t>(out.frame_count) * joints);
  for (int f = 0; f < out.frame_count; ++f) {
    const float time = static_cast<float>(static_cast<double>(f) / rate);
    sample_pose(clip.local, joints, clip.frame_time, std::min(time, static_cast<float>(duration)),
                InterpolationMethod::Slerp, WrapMode::Clamp, out.pose(f));
  }
  return out;
}

Result<Skeleton> add_simulation_root(const Skeleton& source) {
  if (source.find(kSimulationJointName) >= 0) {
    return Error{std::string("the source skeleton already has a joint named '") +
                 kSimulationJointName + "', the name of the simulation root the builder inserts"};
  }
  const int count = source.joint_count();
  std::vector<std::string> names;
  std::vector<int> parents;
  std::vector<Transform> rest;
  names.reserve(count + 1);
  parents.reserve(count + 1);
  rest.reserve(count + 1);
  names.emplace_back(kSimulationJointName);
  parents.push_back(-1);
  rest.push_back(Transform::identity());
  for (int j = 0; j < count; ++j) {
    names.push_back(source.name(j));
    parents.push_back(source.parent(j) < 0 ? 0 : source.parent(j) + 1);
    rest.push_back(source.rest(j));
  }
  return Skeleton::create(std::move(names), std::move(parents), std::move(rest));
}

namespace {

// Every position becomes the mean position and every direction the mean direction (the raw
// directions where they cancel out).
void hold_at_mean(std::vector<glm::vec3>& positions, std::vector<glm::vec3>& directions) {
  glm::dvec3 position(0.0), direction(0.0);
  for (const glm::vec3& p : positions) position += glm::dvec3(p);
  for (const glm::vec3& d : directions) direction += glm::dvec3(d);
  const double n = static_cast<double>(std::max<size_t>(positions.size(), 1));
  std::fill(positions.begin(), positions.end(), glm::vec3(position / n));
  if (glm::length(direction) > 1e-6 * n) {
    std::fill(directions.begin(), directions.end(), glm::vec3(glm::normalize(direction)));
  }
}

}  // namespace

Status preprocess_clip(const Clip& clip, const JointRoleIndices& roles,
                       const PreprocessOptions& options, ProcessedClip& out,
                       PreprocessScratch& scratch) {
  const size_t frames = clip.frame_count > 0 ? static_cast<size_t>(clip.frame_count) : 0;
  const size_t values = frames * static_cast<size_t>(clip.joint_count() + 1);
  out.name = clip.name;
  out.source_path = clip.source_path;
  out.frame_count = clip.frame_count;
  out.joint_count = clip.joint_count() + 1;
  out.frame_time = clip.frame_time;
  out.local_positions.resize(values);
  out.local_rotations.resize(values);
  out.local_velocities.resize(values);
  out.local_angular_velocities.resize(values);
  out.contacts.resize(frames * 2);
  return preprocess_clip(
      clip, roles, options,
      ClipMotionOutput{out.local_positions, out.local_rotations, out.local_velocities,
                       out.local_angular_velocities, out.contacts},
      scratch);
}

Status preprocess_clip(const Clip& clip, const JointRoleIndices& roles,
                       const PreprocessOptions& options, const ClipMotionOutput& out,
                       PreprocessScratch& scratch) {
  const int joints = clip.joint_count();
  const int frames = clip.frame_count;
  const float dt = clip.frame_time;
  const std::string where = "clip '" + clip.name + "': ";
  if (frames <= 0 || joints <= 0 || clip.local.size() != static_cast<size_t>(frames) * joints) {
    return Error{where + "no frames, no joints or a wrong number of local transforms"};
  }
  for (const int j : {roles.hips, roles.left_foot, roles.right_foot}) {
    if (j < 0 || j >= joints) return Error{where + "the hips and feet roles must name joints"};
  }
  for (const int j : {roles.left_toe, roles.right_toe}) {
    if (j >= joints) return Error{where + "a toe role is out of range"};
  }
  const glm::vec3 axis = options.root.hips_forward_axis;
  if (!(glm::length(axis) > 1e-6f) || !std::isfinite(glm::length(axis))) {
    return Error{where + "the hips forward axis must be a finite, non-zero vector"};
  }

  const int out_joints = joints + 1;
  const size_t values = static_cast<size_t>(frames) * out_joints;
  if (out.local_positions.size() != values || out.local_rotations.size() != values ||
      out.local_velocities.size() != values || out.local_angular_velocities.size() != values ||
      out.contacts.size() != static_cast<size_t>(frames) * 2) {
    return Error{where + "the output arrays do not hold frames * (joints + 1) values"};
  }

  // Global transforms (FK) of the joints the root and the contacts need, the source roots and
  // their ancestors; the other joints keep their locals and need no global.
  const std::vector<int>& parents = clip.skeleton.parents();
  scratch.needed.assign(joints, 0);
  for (const int role :
       {roles.hips, roles.left_foot, roles.right_foot, roles.left_toe, roles.right_toe}) {
    for (int j = role; j >= 0 && !scratch.needed[j]; j = parents[j]) scratch.needed[j] = 1;
  }
  for (int j = 0; j < joints; ++j) {
    if (parents[j] < 0) scratch.needed[j] = 1;
  }
  scratch.globals.resize(static_cast<size_t>(frames) * joints);
  for (int f = 0; f < frames; ++f) {
    const std::span<const Transform> pose = clip.pose(f);
    Transform* g = scratch.globals.data() + static_cast<size_t>(f) * joints;
    for (int j = 0; j < joints; ++j) {
      if (!scratch.needed[j]) continue;
      g[j] = parents[j] < 0 ? pose[j] : compose(g[parents[j]], pose[j]);
    }
  }
  auto global = [&](int f, int j) -> const Transform& {
    return scratch.globals[static_cast<size_t>(f) * joints + j];
  };

  // Facing: the hips' forward axis on the ground plane. A frame whose axis points straight up
  // or down has no facing and borrows its nearest neighbour's.
  scratch.directions.resize(frames);
  scratch.positions.resize(frames);
  scratch.smoothed.resize(frames);
  int first_valid = -1;
  for (int f = 0; f < frames; ++f) {
    glm::vec3 d = global(f, roles.hips).rotation * axis;
    d.y = 0.0f;
    const float length = glm::length(d);
    scratch.directions[f] = length > 1e-4f ? d / length : glm::vec3(0.0f);
    if (length > 1e-4f && first_valid < 0) first_valid = f;
    glm::vec3 p = global(f, roles.hips).translation;
    p.y = 0.0f;
    scratch.positions[f] = p;
  }
  const glm::vec3 fallback =
      first_valid >= 0 ? scratch.directions[first_valid] : glm::vec3(0.0f, 0.0f, 1.0f);
  for (int f = 0; f < frames; ++f) {
    if (scratch.directions[f] == glm::vec3(0.0f)) {
      scratch.directions[f] = f > 0 ? scratch.directions[f - 1] : fallback;
    }
  }

  if (options.root.fixed) hold_at_mean(scratch.positions, scratch.directions);
  // Joint 0 positions (smoothed or not) go straight into the output.
  // A held root is already as smooth as it gets (and smoothing would round it differently at
  // the clip's ends).
  const float position_sigma = options.root.fixed ? 0.0f : options.root.position_smoothing / dt;
  const float facing_sigma = options.root.fixed ? 0.0f : options.root.facing_smoothing / dt;
  smooth_gaussian_linear(scratch.positions, position_sigma, scratch.smoothed, scratch.weights);
  for (int f = 0; f < frames; ++f) {
    glm::vec3 p = scratch.smoothed[f];
    p.y = 0.0f;
    out.local_positions[static_cast<size_t>(f) * out_joints] = p;
  }
  smooth_gaussian_linear(scratch.directions, facing_sigma, scratch.smoothed, scratch.weights);

  for (int f = 0; f < frames; ++f) {
    glm::vec3 d = scratch.smoothed[f];
    d.y = 0.0f;
    // Opposite directions inside one window can cancel; the raw direction is then the answer.
    if (glm::length(d) < 1e-3f) d = scratch.directions[f];
    const float yaw = std::atan2(d.x, d.z);
    const glm::quat facing(std::cos(0.5f * yaw), 0.0f, std::sin(0.5f * yaw), 0.0f);
    const size_t base = static_cast<size_t>(f) * out_joints;
    out.local_rotations[base] = facing;
    Transform simulation;
    simulation.rotation = facing;
    simulation.translation = out.local_positions[base];
    const Transform to_simulation = inverse(simulation);
    const std::span<const Transform> pose = clip.pose(f);
    for (int j = 0; j < joints; ++j) {
      if (parents[j] < 0) {
        // Re-rooted: a product of rotations, renormalized against rounding drift.
        const Transform t = compose(to_simulation, global(f, j));
        out.local_positions[base + 1 + j] = t.translation;
        out.local_rotations[base + 1 + j] = glm::normalize(t.rotation);
      } else {
        out.local_positions[base + 1 + j] = pose[j].translation;
        out.local_rotations[base + 1 + j] = pose[j].rotation;
      }
    }
  }

  compute_local_velocities(out.local_positions, out.local_rotations, frames, out_joints, dt,
                           out.local_velocities, out.local_angular_velocities);

  // Contacts: low and slow toe, or low and slow foot.
  const ContactOptions& c = options.contacts;
  scratch.raw_contacts.resize(static_cast<size_t>(frames) * 2);
  auto speed = [&](int f, int j) {
    const int a = std::max(0, f - 1);
    const int b = std::min(frames - 1, f + 1);
    if (a == b) return 0.0f;
    return glm::length(global(b, j).translation - global(a, j).translation) /
           (static_cast<float>(b - a) * dt);
  };
  auto low_and_slow = [&](int f, int j, float height) {
    return j >= 0 && global(f, j).translation.y < height && speed(f, j) < c.speed;
  };
  const int feet[2] = {roles.left_foot, roles.right_foot};
  const int toes[2] = {roles.left_toe, roles.right_toe};
  for (int f = 0; f < frames; ++f) {
    for (int side = 0; side < 2; ++side) {
      scratch.raw_contacts[static_cast<size_t>(side) * frames + f] =
          (low_and_slow(f, toes[side], c.toe_height) || low_and_slow(f, feet[side], c.foot_height))
              ? 1
              : 0;
    }
  }
  int width = clamped_integer<int>(std::round(c.filter_window / dt));
  if (width % 2 == 0) width += 1;
  for (int side = 0; side < 2; ++side) {
    const std::span<const uint8_t> raw = std::span<const uint8_t>(scratch.raw_contacts)
                                             .subspan(static_cast<size_t>(side) * frames, frames);
    if (width <= 1 || !(c.filter_window > 0.0f)) {
      for (int f = 0; f < frames; ++f) out.contacts[static_cast<size_t>(f) * 2 + side] = raw[f];
    } else {
      majority_filter(raw, width, 2, side, out.contacts);
    }
  }
  return Status::success();
}

}  // namespace mm
