"""Prognostics: a per-joint health index from a session's window outputs, its trend across
sessions, and the remaining useful life with an interval. NumPy only: the torch-free monitor
tracks health with it. The ProgPy comparison lives in :mod:`robohealth_mj.prognostics.progpy_rul`
(imported only where ProgPy is installed)."""
