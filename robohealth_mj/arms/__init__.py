"""The arms as data: each arm's description and ratings (``assets/<arm>/``), and placing a push on
its links from the joint torques. NumPy and YAML only: the simulator builds on it and the
torch-free runtime reads it without MuJoCo."""
