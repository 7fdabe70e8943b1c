"""The ROS 1 packages a MoveIt script imports, under their ROS names, for scripts to run without ROS.

A script ports by prefixing its ROS imports (moveit_commander itself is moveplan.commander)::

    import rospy                                  from moveplan.commander.ros import rospy
    import moveit_msgs.msg                        from moveplan.commander.ros import moveit_msgs
    from geometry_msgs.msg import Pose            from moveplan.commander.ros.geometry_msgs.msg import Pose
    from tf.transformations import quaternion_from_euler
                                                  from moveplan.commander.ros.tf.transformations import ...
    import tf2_ros                                from moveplan.commander.ros import tf2_ros
    import moveit_commander                       from moveplan import commander as moveit_commander

Packages: rospy, rostest, genpy, tf (transformations), tf2_ros, and the messages of std_msgs,
geometry_msgs, sensor_msgs, trajectory_msgs, shape_msgs, moveit_msgs, visualization_msgs and
control_msgs;
moveit_ros_planning_interface's MoveGroupInterface, the C++ binding moveit_commander wraps.
"""
