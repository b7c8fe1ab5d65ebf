"""A twin of a real arm: our simulated arm of its type with drive parameters identified from the
arm's own controller log (:mod:`robohealth_mj.twin.identify`), written as a file that ``record``,
``bench`` and every simulation take (``sim.twin=FILE``)."""
