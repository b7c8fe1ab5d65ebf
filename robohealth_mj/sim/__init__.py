"""Physics simulation of the instrumented UR5e: model, control, sensors, curriculum."""

from robohealth_mj.sim.dynamics import gravity_torques

__all__ = ["gravity_torques"]
