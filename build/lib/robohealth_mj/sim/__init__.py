"""Physics simulation of the instrumented UR5e: model, control, sensors, curriculum.

Importing the package imports no MuJoCo: :mod:`robohealth_mj.sim.ratings` is read by the
streaming runtime, which a deployment install runs without the simulator."""
