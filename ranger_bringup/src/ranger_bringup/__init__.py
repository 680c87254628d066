"""ROS-free pieces of ranger_bringup's scripts: keyboard teleop logic and the demo's route and
analysis. The scripts in scripts/ are thin ROS shells around them."""
