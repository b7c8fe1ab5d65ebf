"""The fault catalogue (thesis §2.3.3): six fault modes, their scheduler, and their injection.

Mechanical faults change the physics (drive parameters or applied torques); sensor faults change
what the sensors report; the thesis's analytic signatures can be layered on top (``fault_model``).
"""

from robohealth_mj.faults.catalogue import MECHANICAL, MODES, SENSOR, FaultParameters, Scenario

__all__ = ["MECHANICAL", "MODES", "SENSOR", "FaultParameters", "Scenario"]
