"""The MoveIt workshop's exercises on the UR10e, as a moveit_commander script, run with moveplan.commander.

Only the imports differ from the MoveIt (ROS 1 Noetic) script, and `RobotCommander` names
the robot that `roslaunch` would have loaded (docs/python.md shows the two side by side).
Each exercise is the motion of one CLI sample (samples/ur10e_*.yaml) and lands where it does.

    python samples/ur10e_workshop.py [workshop.mcap]

writes every executed motion to the file given (default workshop.mcap), which
`moveplan inspect`, `moveplan execute --fake` and `moveplan check-tolerances` read.
"""

import sys
from math import pi

from moveplan import commander as moveit_commander
from moveplan.commander.ros import rospy, tf2_ros
from moveplan.commander.ros.geometry_msgs.msg import Pose, PoseStamped, TransformStamped
from moveplan.commander.ros.tf.transformations import quaternion_from_euler


def stamped_pose(frame, x=0.0, y=0.0, z=0.0, roll=0.0, pitch=0.0, yaw=0.0):
    """Return a PoseStamped in `frame`."""
    pose = PoseStamped()
    pose.header.frame_id = frame
    pose.pose.position.x, pose.pose.position.y, pose.pose.position.z = x, y, z
    q = quaternion_from_euler(roll, pitch, yaw)
    pose.pose.orientation.x, pose.pose.orientation.y, pose.pose.orientation.z, pose.pose.orientation.w = q
    return pose


def static_frame(name, parent, x, y, z, roll=0.0, pitch=0.0, yaw=0.0):
    """Return the TransformStamped of a static frame, as static_transform_publisher takes it."""
    t = TransformStamped()
    t.header.frame_id = parent
    t.child_frame_id = name
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = x, y, z
    q = quaternion_from_euler(roll, pitch, yaw)
    t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w = q
    return t


def straight_to(group, pose):
    """Move the tool in a straight line to `pose` (in the planning frame); fail loudly if the line is cut."""
    plan, fraction = group.compute_cartesian_path([pose], 0.01, 0.0)
    if fraction < 1.0:
        raise RuntimeError(f"only {fraction:.0%} of the straight line is possible")
    if not group.execute(plan, wait=True):
        raise RuntimeError("the straight-line motion failed to execute")


def go(group, joints=None):
    """Plan and execute to the target set (or to `joints`); stop the script if either fails."""
    if not group.go(joints, wait=True):
        raise RuntimeError("planning or execution failed")
    group.stop()
    group.clear_pose_targets()


def main(output):
    """Run the six exercises in turn, then save every executed motion to `output`."""
    moveit_commander.roscpp_initialize(sys.argv)
    rospy.init_node("ur10e_workshop", anonymous=True)

    robot = moveit_commander.RobotCommander("ur10e")
    scene = moveit_commander.PlanningSceneInterface()
    group = moveit_commander.MoveGroupCommander("manipulator")
    tf_buffer = tf2_ros.Buffer()
    tf2_ros.TransformListener(tf_buffer)
    broadcaster = tf2_ros.StaticTransformBroadcaster()

    # The cell: the table the robot stands on, a post, and a cube on the table.
    scene.add_box("table", stamped_pose("base_link", 0.3, 0.0, -0.025), size=(1.6, 1.4, 0.04))
    scene.add_cylinder("post", stamped_pose("base_link", -0.4, -0.6, 0.4), height=0.8, radius=0.05)
    scene.add_box("cube", stamped_pose("base_link", 0.2, 0.6, 0.05), size=(0.1, 0.1, 0.1))
    # The targets, published as static transforms (static_transform_publisher in the launch file).
    broadcaster.sendTransform([
        static_frame("target_1", "base_link", 0.6, 0.2, 0.4, roll=pi),
        static_frame("target_2", "base_link", 0.7, -0.2, 0.3, pitch=0.7330383),
        static_frame("object", "base_link", 0.6, -0.4, 0.1),
    ])

    # Exercise 1: home, then two joint goals at reduced scaling, then home again.
    group.set_named_target("home")
    go(group)
    group.set_max_velocity_scaling_factor(0.3)
    group.set_max_acceleration_scaling_factor(0.3)
    go(group, [0.5, -1.2, -1.8, 0.0, 1.57, 0.0])
    group.set_max_velocity_scaling_factor(0.1)
    group.set_max_acceleration_scaling_factor(0.1)
    joint_goal = group.get_current_joint_values()
    joint_goal[:] = [-0.8, -1.0, -2.0, -0.6, 1.57, 0.3]
    go(group, joint_goal)
    group.set_max_velocity_scaling_factor(0.3)
    group.set_max_acceleration_scaling_factor(0.3)
    group.set_named_target("home")
    go(group)

    # Exercise 2: from "ready", the tool 10 cm up.
    group.set_max_velocity_scaling_factor(0.2)
    group.set_max_acceleration_scaling_factor(0.2)
    group.set_named_target("ready")
    go(group)
    group.shift_pose_target(2, 0.10)
    go(group)

    # Exercise 3: from home, to the frame target_1, looked up in tf.
    group.set_max_velocity_scaling_factor(0.3)
    group.set_max_acceleration_scaling_factor(0.3)
    group.set_named_target("home")
    go(group)
    t = tf_buffer.lookup_transform("base_link", "target_1", rospy.Time(0))
    target = Pose()
    target.position.x = t.transform.translation.x
    target.position.y = t.transform.translation.y
    target.position.z = t.transform.translation.z
    target.orientation = t.transform.rotation
    group.set_pose_target(target)
    go(group)

    # Exercise 4: from "ready", approach the tilted target_2 from 10 cm along its own z axis,
    # the tool pointing at it.
    group.set_named_target("ready")
    go(group)
    group.set_pose_target(stamped_pose("target_2", z=0.1, roll=pi))
    go(group)

    # Exercise 5: from "ready", 10 cm along the tool's own x axis, in a straight line.
    group.set_max_velocity_scaling_factor(0.2)
    group.set_max_acceleration_scaling_factor(0.2)
    group.set_named_target("ready")
    go(group)
    along_x = tf_buffer.transform(stamped_pose(group.get_end_effector_link(), x=0.1), "base_link")
    straight_to(group, along_x.pose)

    # Exercise 6: pick and place: from home, 15 cm above the object, onto it, 5 mm into it,
    # 20 cm above it, home.
    group.set_max_velocity_scaling_factor(0.5)
    group.set_max_acceleration_scaling_factor(0.5)
    group.set_named_target("home")
    go(group)
    group.set_pose_target(stamped_pose("object", z=0.15, roll=pi))
    go(group)
    straight_to(group, tf_buffer.transform(stamped_pose("object", roll=pi), "base_link").pose)
    push = group.get_current_pose().pose
    push.position.z -= 0.005  # the tool's z axis points down, into the object
    straight_to(group, push)
    straight_to(group, tf_buffer.transform(stamped_pose("object", z=0.20, roll=pi), "base_link").pose)
    group.set_named_target("home")
    go(group)

    robot.save(output)
    moveit_commander.roscpp_shutdown()


if __name__ == "__main__":
    main(sys.argv[1] if len(sys.argv) > 1 else "workshop.mcap")
