"""Physics simulation of the instrumented UR5e: model, control, sensors, curriculum.

Importing the package imports no MuJoCo. The arms' data lives in :mod:`robohealth_mj.arms`, read
by the streaming runtime, which a deployment install runs without the simulator."""
