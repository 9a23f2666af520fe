// The humanoid joint map: names of every common convention, structure where names are
// ambiguous, map files and their errors.

#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "mm/database/joint_roles.hpp"
#include "mm/offline/bvh.hpp"
#include "mm/offline/preprocess.hpp"
#include "test_support.hpp"

namespace mm {
namespace {

bool contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

// A skeleton from (name, parent name) pairs in parent-before-child order.
Skeleton skeleton_of(const std::vector<std::pair<std::string, std::string>>& joints) {
  std::vector<std::string> names;
  std::vector<int> parents;
  for (const auto& [name, parent] : joints) {
    int p = -1;
    for (size_t i = 0; i < names.size(); ++i) {
      if (names[i] == parent) p = static_cast<int>(i);
    }
    names.push_back(name);
    parents.push_back(p);
  }
  Result<Skeleton> sk = Skeleton::create(names, parents, std::vector<Transform>(names.size()));
  EXPECT_TRUE(sk) << sk.message();
  return *sk;
}

// The joint name each role resolves to ("-" when absent).
std::string role_joint(const Skeleton& sk, const JointRoleIndices& r, std::string_view role) {
  const int j = r.*find_joint_role(role)->index;
  return j >= 0 ? sk.name(j) : "-";
}

void expect_map(const Skeleton& sk, const std::vector<std::pair<std::string, std::string>>& want) {
  Result<JointRoleIndices> r = find_joint_roles(sk, JointRoles{});
  ASSERT_TRUE(r) << r.message();
  for (const auto& [role, joint] : want) EXPECT_EQ(role_joint(sk, *r, role), joint) << role;
}

// CMU as converted to BVH: LeftShoulder is the clavicle, LeftArm the upper arm, Spine1 the chest.
TEST(JointRoles, CmuNamesWithTheClavicleFoundByStructure) {
  const Skeleton sk = skeleton_of({{"Hips", ""},
                                   {"LowerBack", "Hips"},
                                   {"Spine", "LowerBack"},
                                   {"Spine1", "Spine"},
                                   {"Neck", "Spine1"},
                                   {"Neck1", "Neck"},
                                   {"Head", "Neck1"},
                                   {"LeftShoulder", "Spine1"},
                                   {"LeftArm", "LeftShoulder"},
                                   {"LeftForeArm", "LeftArm"},
                                   {"LeftHand", "LeftForeArm"},
                                   {"RightShoulder", "Spine1"},
                                   {"RightArm", "RightShoulder"},
                                   {"RightForeArm", "RightArm"},
                                   {"RightHand", "RightForeArm"},
                                   {"LHipJoint", "Hips"},
                                   {"LeftUpLeg", "LHipJoint"},
                                   {"LeftLeg", "LeftUpLeg"},
                                   {"LeftFoot", "LeftLeg"},
                                   {"LeftToeBase", "LeftFoot"},
                                   {"RHipJoint", "Hips"},
                                   {"RightUpLeg", "RHipJoint"},
                                   {"RightLeg", "RightUpLeg"},
                                   {"RightFoot", "RightLeg"},
                                   {"RightToeBase", "RightFoot"}});
  expect_map(sk, {{"hips", "Hips"},
                  {"spine", "Spine"},
                  {"chest", "Spine1"},
                  {"neck", "Neck"},
                  {"head", "Head"},
                  {"left_shoulder", "LeftShoulder"},
                  {"left_upper_arm", "LeftArm"},
                  {"left_lower_arm", "LeftForeArm"},
                  {"right_hand", "RightHand"},
                  {"left_upper_leg", "LeftUpLeg"},
                  {"right_lower_leg", "RightLeg"},
                  {"left_toe", "LeftToeBase"}});
}

// Mixamo: a namespace prefix, and Spine1 is the middle of three spine joints, not the chest.
TEST(JointRoles, MixamoPrefixAndChestWhereTheArmsBranch) {
  const Skeleton sk = skeleton_of({{"mixamorig:Hips", ""},
                                   {"mixamorig:Spine", "mixamorig:Hips"},
                                   {"mixamorig:Spine1", "mixamorig:Spine"},
                                   {"mixamorig:Spine2", "mixamorig:Spine1"},
                                   {"mixamorig:Neck", "mixamorig:Spine2"},
                                   {"mixamorig:Head", "mixamorig:Neck"},
                                   {"mixamorig:LeftShoulder", "mixamorig:Spine2"},
                                   {"mixamorig:LeftArm", "mixamorig:LeftShoulder"},
                                   {"mixamorig:LeftForeArm", "mixamorig:LeftArm"},
                                   {"mixamorig:LeftHand", "mixamorig:LeftForeArm"},
                                   {"mixamorig:RightShoulder", "mixamorig:Spine2"},
                                   {"mixamorig:RightArm", "mixamorig:RightShoulder"},
                                   {"mixamorig:RightForeArm", "mixamorig:RightArm"},
                                   {"mixamorig:RightHand", "mixamorig:RightForeArm"},
                                   {"mixamorig:LeftUpLeg", "mixamorig:Hips"},
                                   {"mixamorig:LeftLeg", "mixamorig:LeftUpLeg"},
                                   {"mixamorig:LeftFoot", "mixamorig:LeftLeg"},
                                   {"mixamorig:LeftToeBase", "mixamorig:LeftFoot"},
                                   {"mixamorig:RightUpLeg", "mixamorig:Hips"},
                                   {"mixamorig:RightLeg", "mixamorig:RightUpLeg"},
                                   {"mixamorig:RightFoot", "mixamorig:RightLeg"},
                                   {"mixamorig:RightToeBase", "mixamorig:RightFoot"}});
  expect_map(sk, {{"hips", "mixamorig:Hips"},
                  {"spine", "mixamorig:Spine"},
                  {"chest", "mixamorig:Spine2"},
                  {"left_shoulder", "mixamorig:LeftShoulder"},
                  {"left_upper_arm", "mixamorig:LeftArm"},
                  {"right_toe", "mixamorig:RightToeBase"}});
}

// Unreal's mannequin (UE5 has five spine joints: the chest is still where the clavicles hang).
TEST(JointRoles, UnrealMannequinNames) {
  const Skeleton sk = skeleton_of({{"root", ""},
                                   {"pelvis", "root"},
                                   {"spine_01", "pelvis"},
                                   {"spine_02", "spine_01"},
                                   {"spine_03", "spine_02"},
                                   {"spine_04", "spine_03"},
                                   {"spine_05", "spine_04"},
                                   {"neck_01", "spine_05"},
                                   {"head", "neck_01"},
                                   {"clavicle_l", "spine_05"},
                                   {"upperarm_l", "clavicle_l"},
                                   {"lowerarm_l", "upperarm_l"},
                                   {"hand_l", "lowerarm_l"},
                                   {"clavicle_r", "spine_05"},
                                   {"upperarm_r", "clavicle_r"},
                                   {"lowerarm_r", "upperarm_r"},
                                   {"hand_r", "lowerarm_r"},
                                   {"thigh_l", "pelvis"},
                                   {"calf_l", "thigh_l"},
                                   {"foot_l", "calf_l"},
                                   {"ball_l", "foot_l"},
                                   {"thigh_r", "pelvis"},
                                   {"calf_r", "thigh_r"},
                                   {"foot_r", "calf_r"},
                                   {"ball_r", "foot_r"}});
  expect_map(sk, {{"hips", "pelvis"},
                  {"spine", "spine_01"},
                  {"chest", "spine_05"},
                  {"neck", "neck_01"},
                  {"head", "head"},
                  {"left_shoulder", "clavicle_l"},
                  {"right_upper_arm", "upperarm_r"},
                  {"left_lower_arm", "lowerarm_l"},
                  {"left_upper_leg", "thigh_l"},
                  {"left_lower_leg", "calf_l"},
                  {"right_toe", "ball_r"}});
}

// Names that match no candidate: the limbs follow from the feet and hands by structure.
TEST(JointRoles, UnknownLimbNamesAreFoundFromTheFeetAndHands) {
  const Skeleton sk = skeleton_of({{"Hips", ""},
                                   {"Torso", "Hips"},
                                   {"Head", "Torso"},
                                   {"ArmA_L", "Torso"},
                                   {"ArmB_L", "ArmA_L"},
                                   {"Hand_L", "ArmB_L"},
                                   {"ArmA_R", "Torso"},
                                   {"ArmB_R", "ArmA_R"},
                                   {"Hand_R", "ArmB_R"},
                                   {"Femur_L", "Hips"},
                                   {"Tibia_L", "Femur_L"},
                                   {"Foot_L", "Tibia_L"},
                                   {"Phalanx_L", "Foot_L"},
                                   {"Femur_R", "Hips"},
                                   {"Tibia_R", "Femur_R"},
                                   {"Foot_R", "Tibia_R"}});
  expect_map(sk, {{"chest", "Torso"},
                  {"spine", "-"},  // the chest is the hips' own child
                  {"neck", "-"},
                  {"left_shoulder", "-"},  // the upper arms hang off the chest directly
                  {"left_upper_arm", "ArmA_L"},
                  {"left_lower_arm", "ArmB_L"},
                  {"left_upper_leg", "Femur_L"},
                  {"left_lower_leg", "Tibia_L"},
                  {"left_toe", "Phalanx_L"},
                  {"right_toe", "-"}});
}

// The two real skeletons of ../shared/mocap: Bandai, and ReActIdle's rigify-style one (no hands,
// no toes; "face" is the head).
TEST(JointRoles, BandaiAndReActIdleFiles) {
  Result<Clip> bandai = load_bvh(test::clip_path("dataset-2_walk_normal_001"));
  ASSERT_TRUE(bandai) << bandai.message();
  expect_map(bandai->skeleton, {{"hips", "Hips"},
                                {"spine", "Spine"},
                                {"chest", "Chest"},
                                {"neck", "Neck"},
                                {"head", "Head"},
                                {"left_shoulder", "Shoulder_L"},
                                {"left_upper_arm", "UpperArm_L"},
                                {"right_lower_arm", "LowerArm_R"},
                                {"left_hand", "Hand_L"},
                                {"left_upper_leg", "UpperLeg_L"},
                                {"right_lower_leg", "LowerLeg_R"},
                                {"right_toe", "Toes_R"}});
  Result<Clip> idle =
      load_bvh(test::mocap_dir() / "reactidle" / "genuine" / "000_genuine.bvh", BvhOptions{0.0f});
  ASSERT_TRUE(idle) << idle.message();
  expect_map(idle->skeleton, {{"hips", "pelvis"},
                              {"spine", "spine"},
                              {"chest", "spine.001"},
                              {"neck", "neck"},
                              {"head", "face"},
                              {"left_shoulder", "shoulder.L"},
                              {"left_upper_arm", "upper_arm.L"},
                              {"left_lower_arm", "forearm.L"},
                              {"left_hand", "-"},
                              {"left_upper_leg", "thigh.L"},
                              {"left_lower_leg", "shin.L"},
                              {"right_foot", "foot.R"},
                              {"right_toe", "-"}});
}

TEST(JointRoles, LegsThatAreNotOneChainAreRefused) {
  // The feet hang from the hips directly: no joint can be the lower leg.
  const Skeleton sk = skeleton_of({{"Hips", ""},
                                   {"LeftUpLeg", "Hips"},
                                   {"RightUpLeg", "Hips"},
                                   {"LeftFoot", "Hips"},
                                   {"RightFoot", "Hips"}});
  Result<JointRoleIndices> r = find_joint_roles(sk, JointRoles{});
  ASSERT_FALSE(r);
  EXPECT_TRUE(contains(r.message(), "required role 'left_lower_leg'")) << r.message();
  EXPECT_TRUE(contains(r.message(), "left_lower_leg=JOINT")) << r.message();

  // Named, but the upper leg is not above the lower leg.
  const Skeleton crossed = skeleton_of({{"Hips", ""},
                                        {"LeftUpLeg", "Hips"},
                                        {"LeftLeg", "Hips"},
                                        {"LeftFoot", "LeftLeg"},
                                        {"RightUpLeg", "Hips"},
                                        {"RightLeg", "RightUpLeg"},
                                        {"RightFoot", "RightLeg"}});
  r = find_joint_roles(crossed, JointRoles{});
  ASSERT_FALSE(r);
  EXPECT_TRUE(contains(r.message(),
                       "the left leg's joints are not one chain: 'LeftUpLeg' is "
                       "not above 'LeftLeg'"))
      << r.message();
}

TEST(JointMap, LinesCommentsAndOverrides) {
  Result<std::vector<JointRoleAssignment>> map = parse_joint_map(
      "# my rig\n\n  left_foot = l_ankle  # the ankle\nright_foot=r_ankle\n", "rig.map");
  ASSERT_TRUE(map) << map.message();
  ASSERT_EQ(map->size(), 2u);
  EXPECT_EQ((*map)[0].role, "left_foot");
  EXPECT_EQ((*map)[0].joint, "l_ankle");
  EXPECT_EQ((*map)[0].line, 3);
  EXPECT_EQ((*map)[1].joint, "r_ankle");

  const Skeleton sk = skeleton_of({{"Hips", ""},
                                   {"LeftUpLeg", "Hips"},
                                   {"LeftLeg", "LeftUpLeg"},
                                   {"l_ankle", "LeftLeg"},
                                   {"LeftFoot", "LeftLeg"},
                                   {"RightUpLeg", "Hips"},
                                   {"RightLeg", "RightUpLeg"},
                                   {"r_ankle", "RightLeg"}});
  ASSERT_TRUE(check_joint_map(sk, *map));
  JointRoles roles;
  apply_joint_map(roles, *map);
  Result<JointRoleIndices> r = find_joint_roles(sk, roles);
  ASSERT_TRUE(r) << r.message();
  EXPECT_EQ(role_joint(sk, *r, "left_foot"), "l_ankle");  // not the LeftFoot the names give
  EXPECT_EQ(role_joint(sk, *r, "right_foot"), "r_ankle");
}

TEST(JointMap, BadLinesAreRefusedWithFileAndLine) {
  const struct {
    const char* text;
    const char* expected;
  } cases[] = {
      {"hips=Hips\nleft_foot\n", "rig.map:2: expected 'role=Joint', found 'left_foot'"},
      {"\n\nelbow=LeftElbow\n", "rig.map:3: unknown role 'elbow' (roles: hips, spine,"},
      {"left_foot=\n", "rig.map:1: no joint name after 'left_foot='"},
      {"hips=A\nhips=B\n", "rig.map:2: role 'hips' is already given on line 1"},
  };
  for (const auto& c : cases) {
    Result<std::vector<JointRoleAssignment>> map = parse_joint_map(c.text, "rig.map");
    ASSERT_FALSE(map) << c.text;
    EXPECT_TRUE(contains(map.message(), c.expected)) << map.message();
  }
  // A joint the skeleton does not have: the file and line, and the joints there are.
  Result<std::vector<JointRoleAssignment>> map = parse_joint_map("\nhead=Skull\n", "rig.map");
  ASSERT_TRUE(map);
  const Skeleton sk = skeleton_of({{"Hips", ""}, {"Head", "Hips"}});
  const Status s = check_joint_map(sk, *map);
  ASSERT_FALSE(s);
  EXPECT_TRUE(contains(s.message(), "rig.map:2: head=Skull: no joint named 'Skull'"))
      << s.message();
  EXPECT_TRUE(contains(s.message(), "Hips, Head")) << s.message();
  // A missing file names itself.
  Result<std::vector<JointRoleAssignment>> missing = load_joint_map("/nonexistent/rig.map");
  ASSERT_FALSE(missing);
  EXPECT_TRUE(contains(missing.message(), "/nonexistent/rig.map")) << missing.message();
}

}  // namespace
}  // namespace mm
