#!/usr/bin/env bash
# Build the real-world test tier's workspace: eleven public MoveIt 2 config packages and the
# description packages they name, at the commits the tier was written against, laid out as an
# unbuilt colcon workspace's src/ (as their users have them); and, beside it in DIR/peers, MoveIt 1's
# moveit_resources (fanuc, panda, dual panda: the robots MoveIt's own Python tests run on).
#
#   bash tools/get_realworld.sh DIR
#   MOVEPLAN_REALWORLD=DIR/src MOVEPLAN_NOETIC=DIR/peers/moveit_resources_noetic bash .ci/run
#
# Needs git and a network. Each repository is cloned once into DIR/repos, checked out at its
# pinned commit, and only the listed folders are copied into DIR/src/<folder>.
set -euo pipefail

if [[ $# -ne 1 ]]; then
    echo "usage: bash tools/get_realworld.sh DIR" >&2
    exit 2
fi
dir=$(mkdir -p "$1" && cd "$1" && pwd)
base=${MOVEPLAN_GIT_BASE:-https://github.com}

# folder in src/ | owner/repository | commit | folders and files copied (relative to the repository)
packages=(
    "moveit_resources|moveit/moveit_resources|ef5836dd|fanuc_description fanuc_moveit_config panda_description panda_moveit_config dual_arm_panda_moveit_config"
    "Universal_Robots_ROS2_Description|UniversalRobots/Universal_Robots_ROS2_Description|2221ec0f|LICENSE package.xml config meshes urdf"
    "Universal_Robots_ROS2_Driver|UniversalRobots/Universal_Robots_ROS2_Driver|696e1a7b|ur_moveit_config ur_robot_driver/package.xml ur_robot_driver/config"
    "ros2_kortex|Kinovarobotics/ros2_kortex|1fdbef34|kortex_description kortex_moveit_config/kinova_gen3_7dof_robotiq_2f_85_moveit_config kortex_moveit_config/kinova_gen3_lite_moveit_config"
    "ros2_robotiq_gripper|PickNikRobotics/ros2_robotiq_gripper|3b6cf8ff|robotiq_description"
    "abb_ros2|PickNikRobotics/abb_ros2|07057142|abb_resources robot_specific_config/abb_irb1200_support robot_specific_config/abb_irb1200_5_90_moveit_config"
    "franka_ros2|frankarobotics/franka_ros2|dffd70ef|LICENSE franka_bringup franka_fr3_moveit_config"
    "franka_description|frankarobotics/franka_description|566ba44a|LICENSE CMakeLists.txt package.xml end_effectors meshes robots"
    "interbotix_ros_manipulators|Interbotix/interbotix_ros_manipulators|a4b7e511|LICENSE interbotix_ros_xsarms/interbotix_xsarm_control interbotix_ros_xsarms/interbotix_xsarm_descriptions interbotix_ros_xsarms/interbotix_xsarm_moveit interbotix_ros_xsarms/interbotix_xsarm_sim"
    "kuka_robot_descriptions|kroshu/kuka_robot_descriptions|7766e92a|LICENSE kuka_agilus_support kuka_kr_moveit_config kuka_resources"
    "tiago_moveit_config|pal-robotics/tiago_moveit_config|fce71617|LICENSE CMakeLists.txt package.xml config launch module"
    "tiago_robot|pal-robotics/tiago_robot|9c460fbe|LICENSE tiago_controller_configuration tiago_description"
    "pmb2_robot|pal-robotics/pmb2_robot|6fcda269|LICENSE pmb2_description"
    "pal_urdf_utils|pal-robotics/pal_urdf_utils|a8f3bec9|LICENSE CMakeLists.txt package.xml urdf"
    "pal_hey5|pal-robotics/pal_hey5|37e8c542|LICENSE pal_hey5_description"
    "pal_gripper|pal-robotics/pal_gripper|b6336560|LICENSE pal_gripper_description"
    "pal_robotiq_gripper|pal-robotics/pal_robotiq_gripper|f23e1101|LICENSE pal_robotiq_description"
)

# Outside src/: their package names are the ROS 2 moveit_resources' too, and a workspace holds one of each.
peers=(
    "moveit_resources_noetic|moveit/moveit_resources|b771644|fanuc_description fanuc_moveit_config panda_description panda_moveit_config dual_panda_moveit_config"
)

mkdir -p "$dir/repos" "$dir/src" "$dir/peers"
for entry in "${packages[@]/#/src|}" "${peers[@]/#/peers|}"; do
    IFS="|" read -r place folder repository commit paths <<<"$entry"
    clone="$dir/repos/${repository//\//+}"
    if [[ ! -d "$clone/.git" ]]; then
        git clone --quiet "$base/$repository.git" "$clone"
    fi
    git -C "$clone" -c advice.detachedHead=false checkout --quiet "$commit"
    rm -rf "${dir:?}/$place/$folder"
    for path in $paths; do
        mkdir -p "$(dirname "$dir/$place/$folder/$path")"
        cp -R "$clone/$path" "$dir/$place/$folder/$path"
    done
    echo "$place/$folder: $repository @ $commit"
done
echo "workspace ready: MOVEPLAN_REALWORLD=$dir/src MOVEPLAN_NOETIC=$dir/peers/moveit_resources_noetic bash .ci/run"
