// The crowd's level of detail: ranking by significance, tiers under the cost model, and the
// displayed poses (interpolated after reduced-rate updates, blended across changes of step).

#include "mm/controller/crowd_scheduler.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace mm {

namespace {

constexpr std::array<std::string_view, kCrowdTierCount> kTierNames = {"full", "half", "quarter",
                                                                      "move_only"};
constexpr std::array<int, kCrowdTierCount> kTierPeriods = {1, 2, 4, 0};
// A blend this far gone shows the new pose alone.
constexpr float kBlendDone = 1e-3f;
// More element moves than this per character in the insertion sort of an almost-sorted order
// (the usual frame) means the order changed much: sort afresh.
constexpr size_t kInsertionMovesPerCharacter = 8;

// The shorter-arc sign of `q` next to `reference`.
glm::quat aligned(const glm::quat& q, const glm::quat& reference) {
  return glm::dot(q, reference) < 0.0f ? -q : q;
}

}  // namespace

std::string_view crowd_tier_name(CrowdTier tier) {
  return kTierNames[static_cast<size_t>(tier)];
}

int crowd_tier_period(CrowdTier tier) {
  return kTierPeriods[static_cast<size_t>(tier)];
}

Status CrowdSchedulerSettings::validate() const {
  if (!std::isfinite(budget_ms) && !(budget_ms > 0.0f)) {
    return Error{"crowd scheduler: budget_ms must be a number >= 0 (0 or infinite: no budget)"};
  }
  if (!(budget_ms >= 0.0f)) return Error{"crowd scheduler: budget_ms must be >= 0"};
  if (threads < 1 || threads > 1024) return Error{"crowd scheduler: threads in [1, 1024]"};
  for (size_t t = 0; t < cost_us.size(); ++t) {
    if (!std::isfinite(cost_us[t]) || !(cost_us[t] > 0.0f)) {
      return Error{"crowd scheduler: the cost of tier " + std::string(kTierNames[t]) +
                   " must be a positive number of us"};
    }
    if (t > 0 && cost_us[t] > cost_us[t - 1]) {
      return Error{"crowd scheduler: the cost of tier " + std::string(kTierNames[t]) +
                   " is above the cost of tier " + std::string(kTierNames[t - 1])};
    }
  }
  if (!(full_share >= 0.0f && full_share <= 1.0f)) {
    return Error{"crowd scheduler: full_share must be in [0, 1]"};
  }
  if (!(headroom >= 0.0f && headroom < 1.0f)) {
    return Error{"crowd scheduler: headroom must be in [0, 1)"};
  }
  if (!std::isfinite(hysteresis) || !(hysteresis >= 0.0f)) {
    return Error{"crowd scheduler: hysteresis must be a number >= 0"};
  }
  if (!std::isfinite(blend_halflife) || !(blend_halflife > 0.0f)) {
    return Error{"crowd scheduler: blend_halflife must be a positive number of seconds"};
  }
  return Status::success();
}

Result<CrowdScheduler> CrowdScheduler::create(size_t characters, size_t joints,
                                              const CrowdSchedulerSettings& settings) {
  if (Status valid = settings.validate(); !valid) return Error{valid.message()};
  if (characters == 0 || characters > std::numeric_limits<uint32_t>::max()) {
    return Error{"crowd scheduler: at least one character (and fewer than 2^32)"};
  }
  if (joints == 0) return Error{"crowd scheduler: at least one joint"};
  CrowdScheduler s;
  s.settings_ = settings;
  s.joints_ = joints;
  s.tier_.assign(characters, static_cast<uint8_t>(CrowdTier::Full));
  s.last_step_.assign(characters, Step::None);
  s.held_frames_.assign(characters, 0);
  s.pending_dt_.assign(characters, 0.0f);
  s.update_period_.assign(characters, 1);
  s.blend_weight_.assign(characters, 0.0f);
  s.shows_last_.assign(characters, 0);
  s.carried_.assign(characters, 0);
  s.carry_.assign(characters, Transform{});
  s.keys_.assign(characters, 0.0f);
  s.order_.resize(characters);
  for (size_t i = 0; i < characters; ++i) s.order_[i] = static_cast<uint32_t>(i);
  const size_t poses = characters * joints;
  s.last_.resize(poses);
  s.from_.resize(poses);
  s.offset_translations_.assign(poses, glm::vec3(0.0f));
  s.offset_rotations_.assign(poses, glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
  s.shown_.resize(poses);
  s.counts_[0] = static_cast<int>(characters);
  return s;
}

// ---- Planning --------------------------------------------------------------------------------

void CrowdScheduler::plan(std::span<const float> significance) {
  MM_ASSERT(significance.size() == tier_.size());
  const double capacity =
      static_cast<double>(settings_.budget_ms) * 1000.0 * static_cast<double>(settings_.threads);
  // What the plan may spend: the capacity less the headroom kept for frames dearer than the
  // model says.
  const double spendable = capacity * (1.0 - static_cast<double>(settings_.headroom));
  const double n = static_cast<double>(tier_.size());
  if (settings_.budget_ms == 0.0f || !std::isfinite(capacity) ||
      n * settings_.cost_us[0] <= spendable) {
    plan_all(CrowdTier::Full);
    return;
  }
  ++frame_;
  // The floor: the highest tier every character can have within the budget (MoveOnly when
  // none can: over budget, the least work there is).
  CrowdTier floor = CrowdTier::MoveOnly;
  for (int t = 1; t < kCrowdTierCount; ++t) {
    if (n * settings_.cost_us[static_cast<size_t>(t)] <= spendable) {
      floor = static_cast<CrowdTier>(t);
      break;
    }
  }
  rank(significance);
  assign(floor, capacity, spendable);
}

void CrowdScheduler::plan_all(CrowdTier tier) {
  ++frame_;
  std::fill(tier_.begin(), tier_.end(), static_cast<uint8_t>(tier));
  counts_.fill(0);
  counts_[static_cast<size_t>(tier)] = static_cast<int>(tier_.size());
  planned_cost_us_ =
      static_cast<double>(tier_.size()) * settings_.cost_us[static_cast<size_t>(tier)];
}

Status CrowdScheduler::set_budget_ms(float budget_ms) {
  CrowdSchedulerSettings changed = settings_;
  changed.budget_ms = budget_ms;
  if (Status valid = changed.validate(); !valid) return valid;
  settings_ = changed;
  return Status::success();
}

// order_ by key (significance plus the hysteresis of the tier held), most significant first and
// the lower index first among equals: a strict order, so any sort gives the same permutation.
void CrowdScheduler::rank(std::span<const float> significance) {
  constexpr float kLeast = -std::numeric_limits<float>::max();
  for (size_t i = 0; i < tier_.size(); ++i) {
    const float s = std::isfinite(significance[i]) ? significance[i] : kLeast;
    const float held = static_cast<float>(kCrowdTierCount - 1 - tier_[i]);
    keys_[i] = s == kLeast ? kLeast : s + settings_.hysteresis * held;
  }
  auto before = [this](uint32_t a, uint32_t b) {
    return keys_[a] > keys_[b] || (keys_[a] == keys_[b] && a < b);
  };
  // Last frame's order is almost sorted: an insertion sort costs little, unless much changed.
  const size_t budget = kInsertionMovesPerCharacter * order_.size();
  size_t moves = 0;
  for (size_t k = 1; k < order_.size() && moves <= budget; ++k) {
    const uint32_t item = order_[k];
    size_t j = k;
    for (; j > 0 && before(item, order_[j - 1]) && moves <= budget; --j, ++moves) {
      order_[j] = order_[j - 1];
    }
    order_[j] = item;
  }
  if (moves > budget) std::sort(order_.begin(), order_.end(), before);
}

// Everyone at the floor; then the most significant at full rate, within full_share of the
// capacity; then the rest raised a tier at a time, in rank order, while what may be spent
// lasts. Each pass stops at the first character it cannot raise, so tiers never rise with rank.
void CrowdScheduler::assign(CrowdTier floor, double capacity, double spendable) {
  const auto& cost = settings_.cost_us;
  const size_t n = order_.size();
  const size_t lowest = static_cast<size_t>(floor);
  std::fill(tier_.begin(), tier_.end(), static_cast<uint8_t>(lowest));
  double spent = static_cast<double>(n) * cost[lowest];
  const double full_capacity = static_cast<double>(settings_.full_share) * capacity;
  size_t top = 0;
  for (; top < n; ++top) {
    const double raise = cost[0] - cost[lowest];
    if (static_cast<double>(top + 1) * cost[0] > full_capacity || spent + raise > spendable) {
      break;
    }
    tier_[order_[top]] = 0;
    spent += raise;
  }
  for (size_t level = lowest; level-- > 0;) {
    const double raise = cost[level] - cost[level + 1];
    for (size_t r = top; r < n && tier_[order_[r]] == level + 1; ++r) {
      if (spent + raise > spendable) break;
      tier_[order_[r]] = static_cast<uint8_t>(level);
      spent += raise;
    }
  }
  counts_.fill(0);
  for (const uint8_t t : tier_) ++counts_[t];
  planned_cost_us_ = spent;
}

// ---- Stepping --------------------------------------------------------------------------------

bool CrowdScheduler::updates(size_t i) const {
  const CrowdTier t = tier(i);
  if (t == CrowdTier::MoveOnly || t == CrowdTier::Full) return true;
  const int64_t period = crowd_tier_period(t);
  return (frame_ + static_cast<int64_t>(i)) % period == 0 || held_frames_[i] + 1 >= period;
}

void CrowdScheduler::prefetch_ahead(size_t i, const Controller& controller) const {
  // A full update's own memory traffic dwarfs the latency this hides; a move is all latency.
  if (tier(i) == CrowdTier::MoveOnly) controller.prefetch_move_only_members();
}

void CrowdScheduler::prefetch(size_t i, const Controller& controller) const {
  constexpr size_t kLine = 64;
  const auto lines = [](const void* begin, size_t bytes) {
    const char* first = static_cast<const char*>(begin);
    for (size_t offset = 0; offset < bytes; offset += kLine) __builtin_prefetch(first + offset, 1);
  };
  // A full update's own memory traffic dwarfs the latency this hides; a move is all latency,
  // and touches only the held pose's root and the carry (after its first step).
  if (tier(i) == CrowdTier::MoveOnly) {
    lines(last_.data() + i * joints_, sizeof(Transform));
    lines(carry_.data() + i, sizeof(Transform));
    controller.prefetch_move_only();
    return;
  }
  const size_t bytes = joints_ * sizeof(Transform);
  lines(last_.data() + i * joints_, bytes);
  lines(shown_.data() + i * joints_, bytes);
}

void CrowdScheduler::displayed_pose(size_t i, std::span<Transform> out) const {
  MM_ASSERT(out.size() == joints_);
  const std::span<const Transform> shown = pose(i);
  if (!(shows_last_[i] != 0 && carried_[i] != 0)) {
    std::copy(shown.begin(), shown.end(), out.begin());
    return;
  }
  for (size_t j = 0; j < joints_; ++j) out[j] = compose(carry_[i], shown[j]);
}

void CrowdScheduler::step(size_t i, Controller& controller, float dt,
                          const ControllerInput& input) {
  const std::span<const Transform> globals = controller.global_transforms();
  MM_ASSERT(globals.size() == joints_);
  const size_t base = i * joints_;
  const auto pose_begin = [base](std::vector<Transform>& poses) {
    return poses.begin() + static_cast<std::ptrdiff_t>(base);
  };
  if (last_step_[i] == Step::None) {
    controller.settle_carried_pose();
    for (std::vector<Transform>* pose : {&from_, &last_, &shown_}) {
      std::copy(globals.begin(), globals.end(), pose_begin(*pose));
    }
  }
  if (!(dt > 0.0f) || !std::isfinite(dt)) return;
  const Step last_step = last_step_[i];
  const CrowdTier t = tier(i);
  const Step now = !updates(i) ? Step::Hold : t == CrowdTier::MoveOnly ? Step::Move : Step::Update;
  float& weight = blend_weight_[i];
  weight *= std::exp2(-dt / settings_.blend_halflife);
  if (weight < kBlendDone) weight = 0.0f;
  pending_dt_[i] += dt;
  if (now == Step::Hold) {
    ++held_frames_[i];
    last_step_[i] = Step::Hold;
    show(i);
    return;
  }
  // A reduced-rate update chases from what is shown, so it never jumps; a step that shows the
  // controller's pose at once (full rate, a move) jumps unless it continues the same kind of
  // step: it starts a blend from what was shown on the frame before.
  const bool at_once = now == Step::Move || crowd_tier_period(t) == 1;
  const bool continues = last_step == now && update_period_[i] == 1;
  const bool blends = at_once && !continues && last_step != Step::None;
  // What is shown now: where a chase starts, or what a blend eases from.
  if (blends || !at_once) {
    displayed_pose(i, std::span<Transform>(&*pose_begin(from_), joints_));
  }
  if (now == Step::Move) {
    controller.update_move_only(pending_dt_[i], input);
  } else {
    controller.update(pending_dt_[i], input);
  }
  keep_update(i, controller, now, last_step);
  update_period_[i] = static_cast<uint8_t>(at_once ? 1 : crowd_tier_period(t));
  pending_dt_[i] = 0.0f;
  held_frames_[i] = 0;
  last_step_[i] = now;
  if (blends) start_blend(i, std::span<const Transform>(&*pose_begin(from_), joints_));
  show(i);
}

// last_ and the carry after character i's step: the controller's pose, or, when the step only
// moved it, the held pose (copied once, when the holding starts) and the rigid motion from
// where it hangs to the controller's root.
void CrowdScheduler::keep_update(size_t i, const Controller& controller, Step now, Step last_step) {
  const std::span<const Transform> globals = controller.global_transforms();
  Transform& held_root = last_[i * joints_];
  if (now != Step::Move || !controller.pose_carried()) {
    std::copy(globals.begin(), globals.end(), &held_root);
    carried_[i] = 0;
    return;
  }
  const Transform from = controller.carried_from();
  const bool same_hold = last_step == Step::Move && carried_[i] != 0 &&
                         held_root.translation == from.translation &&
                         held_root.rotation == from.rotation;
  if (!same_hold) {
    std::copy(globals.begin(), globals.end(), &held_root);
    held_root = from;
  }
  const Transform& root = globals[0];
  Transform& carry = carry_[i];
  carry.rotation = glm::normalize(root.rotation * glm::conjugate(from.rotation));
  carry.translation = root.translation - carry.rotation * from.translation;
  carried_[i] = 1;
}

// Offsets from the new pose (last_) to `predicted`, per joint in world space, at full weight.
void CrowdScheduler::start_blend(size_t i, std::span<const Transform> predicted) {
  const size_t base = i * joints_;
  for (size_t j = 0; j < joints_; ++j) {
    const Transform now = updated_joint(i, j);
    offset_translations_[base + j] = predicted[j].translation - now.translation;
    offset_rotations_[base + j] =
        aligned(predicted[j].rotation * glm::conjugate(now.rotation), glm::quat(1, 0, 0, 0));
  }
  blend_weight_[i] = 1.0f;
}

// shown_ of character i: the chase from the pose shown at the last update to that update's
// pose, over the update's period (lerp and nlerp: the steps are short), plus the blend's
// offsets at their weight.
void CrowdScheduler::show(size_t i) {
  const size_t base = i * joints_;
  const std::span<Transform> out(shown_.data() + base, joints_);
  const float s = std::min(
      1.0f, static_cast<float>(held_frames_[i] + 1) / static_cast<float>(update_period_[i]));
  const float w = blend_weight_[i];
  // The update's pose as it is: shown from last_ itself, without a copy.
  shows_last_[i] = s == 1.0f && w == 0.0f;
  if (shows_last_[i]) return;
  if (s == 1.0f) {
    for (size_t j = 0; j < joints_; ++j) out[j] = updated_joint(i, j);
  } else {
    for (size_t j = 0; j < joints_; ++j) {
      const Transform& a = from_[base + j];
      const Transform b = updated_joint(i, j);
      out[j].translation = a.translation + (b.translation - a.translation) * s;
      const glm::quat from = aligned(a.rotation, b.rotation);
      out[j].rotation = glm::normalize(from + (b.rotation - from) * s);
      out[j].scale = b.scale;
    }
  }
  if (w == 0.0f) return;
  const glm::quat identity(1.0f, 0.0f, 0.0f, 0.0f);
  for (size_t j = 0; j < joints_; ++j) {
    out[j].translation += offset_translations_[base + j] * w;
    const glm::quat& q = offset_rotations_[base + j];
    out[j].rotation =
        glm::normalize(glm::normalize(identity + (q - identity) * w) * out[j].rotation);
  }
}

}  // namespace mm
