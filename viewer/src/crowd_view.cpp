#include "crowd_view.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <glm/gtc/constants.hpp>

#include "mm/runtime/transform.hpp"

namespace mm::viewer {
namespace {

// A bone's box is this fraction of its length wide, within these limits (m): limbs look like
// limbs and the short spine and toe bones do not vanish.
constexpr float kWidthPerLength = 0.35f;
constexpr float kMinWidth = 0.035f, kMaxWidth = 0.11f;
// The head: a box this long above the head joint, along the neck, and this wide.
constexpr float kHeadLength = 0.22f, kHeadWidth = 0.17f;

// A well-mixed 32-bit hash of i (so neighbours on the spiral face unrelated ways).
uint32_t mix(uint32_t x) {
  x ^= x >> 16;
  x *= 0x7feb352dU;
  x ^= x >> 15;
  x *= 0x846ca68bU;
  x ^= x >> 16;
  return x;
}

// Where `p` goes under the rigid motion `carry` (rotation, then translation).
Transform carried(const Transform& carry, const Transform& p) {
  Transform out = p;
  out.translation = carry.rotation * p.translation + carry.translation;
  out.rotation = carry.rotation * p.rotation;
  return out;
}

// The box from a to b, its width axes turned with `turn`.
void bone_box(const glm::vec3& a, const glm::vec3& b, const glm::quat& turn, float width,
              const glm::vec4& colour, BoneInstance& out) {
  const glm::vec3 along = b - a;
  const float length = glm::length(along);
  const glm::vec3 y = length > 1e-6f ? along / length : glm::vec3(0.0f, 1.0f, 0.0f);
  glm::vec3 x = turn * glm::vec3(1.0f, 0.0f, 0.0f);
  x -= y * glm::dot(x, y);
  if (glm::dot(x, x) < 1e-8f) {
    x = std::abs(y.x) < 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 0.0f, 1.0f);
    x -= y * glm::dot(x, y);
  }
  x = glm::normalize(x);
  const glm::vec3 z = glm::cross(x, y);
  out.model[0] = glm::vec4(x * width, 0.0f);
  out.model[1] = glm::vec4(y * length, 0.0f);
  out.model[2] = glm::vec4(z * width, 0.0f);
  out.model[3] = glm::vec4(a, 1.0f);
  out.colour = colour;
}

// Smooths a timing over about `frames` samples (the first sample is taken as it is).
void smooth(float& mean, float sample, float frames = 60.0f) {
  mean = mean == 0.0f ? sample : mean + (sample - mean) / frames;
}

}  // namespace

glm::vec3 crowd_start_position(size_t i, float spacing) {
  // Vogel's spiral: the k-th point at radius ~ sqrt(k) and the golden angle apart, so every
  // character has about spacing^2 of ground around it.
  const float golden = glm::pi<float>() * (3.0f - std::sqrt(5.0f));
  const float k = static_cast<float>(i) + 0.5f;
  const float r = spacing * std::sqrt(k / glm::pi<float>());
  const float angle = golden * static_cast<float>(i);
  return glm::vec3(r * std::cos(angle), 0.0f, r * std::sin(angle));
}

float crowd_start_yaw(size_t i) {
  const uint32_t h = mix(static_cast<uint32_t>(i) * 2654435761U + 1U);
  return (static_cast<float>(h) / 4294967296.0f) * glm::two_pi<float>() - glm::pi<float>();
}

glm::vec3 crowd_tier_colour(CrowdTier tier) {
  switch (tier) {
    case CrowdTier::Full:
      return {0.20f, 0.72f, 0.30f};
    case CrowdTier::Half:
      return {0.25f, 0.50f, 0.95f};
    case CrowdTier::Quarter:
      return {0.95f, 0.72f, 0.15f};
    case CrowdTier::MoveOnly:
      return {0.85f, 0.22f, 0.22f};
  }
  return {1.0f, 1.0f, 1.0f};
}

size_t crowd_bones_per_character(std::span<const int> parents) {
  const size_t with_parent = static_cast<size_t>(
      std::count_if(parents.begin(), parents.end(), [](int p) { return p >= 0; }));
  return with_parent + 1;
}

void pack_bone_instances(std::span<const Transform> pose, const Transform& carry,
                         std::span<const int> parents, int head, const glm::vec4& colour,
                         std::span<BoneInstance> out) {
  size_t k = 0;
  for (size_t j = 0; j < pose.size(); ++j) {
    const int p = parents[j];
    if (p < 0) continue;
    const Transform a = carried(carry, pose[static_cast<size_t>(p)]);
    const Transform b = carried(carry, pose[j]);
    const float length = glm::length(b.translation - a.translation);
    const float width = std::clamp(kWidthPerLength * length, kMinWidth, kMaxWidth);
    bone_box(a.translation, b.translation, a.rotation, width, colour, out[k++]);
  }
  // The head, along the neck beyond the head joint; without a head joint, a box at the root.
  const size_t h = head >= 0 ? static_cast<size_t>(head) : 0;
  const Transform top = carried(carry, pose[h]);
  const int neck = parents[h];
  glm::vec3 up(0.0f, 1.0f, 0.0f);
  if (neck >= 0) {
    const glm::vec3 along =
        top.translation - carried(carry, pose[static_cast<size_t>(neck)]).translation;
    if (glm::dot(along, along) > 1e-8f) up = glm::normalize(along);
  }
  bone_box(top.translation, top.translation + up * kHeadLength, top.rotation, kHeadWidth, colour,
           out[k]);
}

Result<std::unique_ptr<CrowdView>> CrowdView::create(
    std::shared_ptr<const ControllerDatabase> shared, const ControllerSettings& settings,
    const CrowdViewSettings& crowd) {
  if (crowd.characters < 1) return Error{"crowd: at least one character"};
  const Database& db = shared->database();
  std::unique_ptr<CrowdView> view(new CrowdView());
  CrowdSchedulerSettings lod;
  lod.budget_ms = crowd.budget_ms;
  Result<CrowdScheduler> scheduler = CrowdScheduler::create(
      static_cast<size_t>(crowd.characters), static_cast<size_t>(db.joint_count()), lod);
  if (!scheduler) return Error{"crowd: " + scheduler.message()};
  view->scheduler_.emplace(std::move(scheduler).value());
  // What is drawn is the scheduler's pose: the controllers' own skinning is not needed.
  ControllerSettings crowd_settings = settings;
  crowd_settings.compute_skinning = false;
  const size_t n = static_cast<size_t>(crowd.characters);
  view->controllers_.reserve(n);
  view->scripts_.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    Result<Controller> c = Controller::create(shared, crowd_settings);
    if (!c) return Error{"crowd: " + c.message()};
    c->teleport(crowd_start_position(i, crowd.spacing), crowd_start_yaw(i));
    view->controllers_.push_back(std::move(c).value());
    view->scripts_.push_back(varied_input_script(static_cast<uint32_t>(i), crowd.script_seconds));
  }
  view->shared_ = std::move(shared);
  view->significance_.assign(n, 0.0f);
  view->parents_ = db.skeleton().parents();
  view->head_ = db.roles().head;
  view->script_seconds_ = crowd.script_seconds;
  view->radius_ = glm::length(crowd_start_position(n - 1, crowd.spacing));
  return view;
}

Status CrowdView::set_budget_ms(float ms) {
  return scheduler_->set_budget_ms(ms);
}

void CrowdView::step(float dt, const glm::vec3& camera) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  for (size_t i = 0; i < controllers_.size(); ++i) {
    const glm::vec3 p = controllers_[i].root_transform().translation;
    significance_[i] = -glm::distance(glm::vec2(p.x, p.z), glm::vec2(camera.x, camera.z));
  }
  scheduler_->plan(significance_);
  time_ += dt;
  const float t = std::fmod(time_, script_seconds_);
  for (size_t i = 0; i < controllers_.size(); ++i) {
    if (i + 2 < controllers_.size()) scheduler_->prefetch_ahead(i + 2, controllers_[i + 2]);
    if (i + 1 < controllers_.size()) scheduler_->prefetch(i + 1, controllers_[i + 1]);
    const ControllerInput input = scheduler_->updates(i) ? scripts_[i].at(t) : ControllerInput{};
    scheduler_->step(i, controllers_[i], dt, input);
  }
  smooth(update_ms_, std::chrono::duration<float, std::milli>(Clock::now() - start).count());
}

void CrowdView::pack(bool tier_colours, std::vector<BoneInstance>& out) const {
  const size_t per = crowd_bones_per_character(parents_);
  out.resize(per * controllers_.size());
  const glm::vec4 plain(0.72f, 0.60f, 0.50f, 1.0f);
  for (size_t i = 0; i < controllers_.size(); ++i) {
    const glm::vec4 colour =
        tier_colours ? glm::vec4(crowd_tier_colour(scheduler_->tier(i)), 1.0f) : plain;
    pack_bone_instances(scheduler_->pose(i), scheduler_->carry(i), parents_, head_, colour,
                        std::span<BoneInstance>(out.data() + i * per, per));
  }
}

}  // namespace mm::viewer
