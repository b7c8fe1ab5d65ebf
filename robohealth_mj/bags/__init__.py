"""ROS 2 bags (rosbag2, MCAP storage) in and out, with standard message types only."""
