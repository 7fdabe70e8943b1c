"""ROS 2 message definitions per distro, as rosbag2 stores them as MCAP schemas (see README.md here)."""
