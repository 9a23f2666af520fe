#include "scene.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

#include "mm/runtime/interpolation.hpp"

namespace mm::viewer {
namespace {

const glm::vec3 kBodyColour{0.72f, 0.60f, 0.50f};

// Exponential smoothing of a timing over about `frames` samples.
void smooth(float& mean, float sample, float frames = 60.0f) {
  mean += (sample - mean) / frames;
}

Result<std::unique_ptr<Controller>> make_controller(
    std::shared_ptr<const ControllerDatabase> shared, const ControllerSettings& settings) {
  Result<Controller> controller = Controller::create(std::move(shared), settings);
  if (!controller) return controller.error();
  return std::make_unique<Controller>(std::move(*controller));
}

}  // namespace

Result<std::unique_ptr<Scene>> Scene::create(std::shared_ptr<const Database> database,
                                             const ControllerSettings& settings, SkinnedMesh body,
                                             WeightMethod body_weights, ReweighFunction reweigh) {
  if (!body.bind_global.empty() &&
      body.bind_global.size() != static_cast<size_t>(database->joint_count())) {
    return Error{"viewer: the body has " + std::to_string(body.bind_global.size()) +
                 " joints, the database " + std::to_string(database->joint_count())};
  }
  Result<std::shared_ptr<const ControllerDatabase>> shared = ControllerDatabase::create(database);
  if (!shared) return shared.error();
  Result<std::unique_ptr<Controller>> controller = make_controller(*shared, settings);
  if (!controller) return controller.error();
  std::unique_ptr<Scene> scene(new Scene(std::move(body)));
  scene->database_ = std::move(database);
  scene->shared_ = std::move(*shared);
  scene->controller_ = std::move(*controller);
  scene->reweigh_ = std::move(reweigh);
  scene->weight_method_ = body_weights;
  return scene;
}

void Scene::step(float dt, const ControllerInput& input, SkinningMethod skinning) {
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  controller_->update(dt, input);
  smooth(times_.update, std::chrono::duration<float>(Clock::now() - start).count());
  const ControllerDebug& d = controller_->debug();
  if (d.searched) smooth(times_.search, d.search_seconds, 10.0f);
  if (!body_.mesh().mesh.positions.empty()) body_.pose(controller_->global_transforms(), skinning);
  time_ += dt;
  record_sample();
}

void Scene::note_frame_time(float seconds) {
  if (times_.frame == 0.0f) times_.frame = seconds;
  smooth(times_.frame, seconds, 30.0f);
}

void Scene::record_sample() {
  const ControllerDebug& d = controller_->debug();
  const Transform& root = controller_->root_transform();
  RunSample s;
  s.time = time_;
  s.simulation = d.world(d.simulation_position);
  s.character = root.translation;
  const glm::vec3 forward = root.rotation * glm::vec3(0.0f, 0.0f, 1.0f);
  s.character_facing = glm::vec2(forward.x, forward.z);
  const int toes[2] = {database_->roles().left_toe, database_->roles().right_toe};
  for (int side = 0; side < 2; ++side) {
    if (toes[side] >= 0) s.toes[side] = controller_->global_transforms()[toes[side]].translation;
    s.contact[side] = d.contact[side];
  }
  s.transition = d.transitions != last_transitions_;
  last_transitions_ = d.transitions;
  s.standing = d.standing;
  run_.push_back(s);
}

void Scene::draw(Renderer& renderer, const GlContext& context, const OrbitCamera& camera,
                 bool show_body) {
  int width = 0, height = 0;
  context.framebuffer_size(width, height);
  const CameraMatrices matrices = camera.matrices(width, height);
  renderer.begin(context.framebuffer(), width, height);
  if (world_) {
    if (!level_uploaded_) {
      renderer.set_level(level_positions_, level_indices_);
      level_uploaded_ = true;
    }
    renderer.draw_level(matrices);
  } else {
    renderer.draw_ground(matrices, camera.target);
  }
  lines_.clear();
  draw_controller_debug(*controller_, toggles, lines_);
  renderer.draw_lines(matrices, lines_, false);
  if (show_body) {
    renderer.draw_body(matrices, body_.positions(), body_.normals(), kBodyColour,
                       controller_->debug().ground_height);
  }
  if (toggles.skeleton || !show_body || body_.positions().empty()) {
    lines_.clear();
    draw_skeleton(*controller_, lines_);
    renderer.draw_lines(matrices, lines_, true);
  }
}

glm::vec4 Scene::screen_box(const OrbitCamera& camera, int width, int height) const {
  const CameraMatrices m = camera.matrices(width, height);
  const glm::mat4 to_clip = m.projection * m.view;
  glm::vec4 box(1e9f, 1e9f, -1e9f, -1e9f);
  auto add = [&](const glm::vec3& p) {
    const glm::vec4 clip = to_clip * glm::vec4(p, 1.0f);
    if (clip.w <= 0.0f) return;
    const float x = (clip.x / clip.w * 0.5f + 0.5f) * static_cast<float>(width);
    const float y = (0.5f - clip.y / clip.w * 0.5f) * static_cast<float>(height);
    box = glm::vec4(std::min(box.x, x), std::min(box.y, y), std::max(box.z, x), std::max(box.w, y));
  };
  if (!body_.positions().empty()) {
    for (const glm::vec3& p : body_.positions()) add(p);
  } else {
    for (const Transform& t : controller_->global_transforms()) add(t.translation);
  }
  return box;
}

Status Scene::apply_settings(const ControllerSettings& settings) {
  return controller_->set_settings(settings);
}

Status Scene::set_channel_weight(int channel, float weight) {
  Result<Database> created = with_channel_weight(*database_, channel, weight);
  if (!created) return Error{"viewer: " + created.message()};
  auto reweighted = std::make_shared<const Database>(std::move(created).value());
  Result<std::shared_ptr<const ControllerDatabase>> shared =
      ControllerDatabase::create(reweighted, shared_->options());
  if (!shared) return Error{shared.message()};
  Result<std::unique_ptr<Controller>> controller =
      make_controller(*shared, controller_->settings());
  if (!controller) return Error{controller.message()};
  const Transform root = controller_->root_transform();
  (*controller)->set_world(world_);
  (*controller)->teleport(root.translation, quat_yaw(root.rotation));
  database_ = std::move(reweighted);
  shared_ = std::move(*shared);
  controller_ = std::move(*controller);
  last_transitions_ = 0;
  return Status::success();
}

void Scene::set_level(const WorldQueries* world, std::vector<glm::vec3> positions,
                      std::vector<uint32_t> indices) {
  world_ = world;
  level_positions_ = std::move(positions);
  level_indices_ = std::move(indices);
  level_uploaded_ = false;
  controller_->set_world(world_);
}

Status Scene::set_weight_method(WeightMethod method) {
  if (!reweigh_) return Error{"viewer: the loaded body's weights are its own"};
  Result<std::vector<VertexInfluences>> influences = reweigh_(method);
  if (!influences) return Error{influences.message()};
  body_.set_influences(std::move(*influences));
  weight_method_ = method;
  return Status::success();
}

}  // namespace mm::viewer
