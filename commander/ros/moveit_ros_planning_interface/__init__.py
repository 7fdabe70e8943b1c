"""moveit_ros_planning_interface: the C++ bindings moveit_commander wraps, for scripts that use them directly."""
