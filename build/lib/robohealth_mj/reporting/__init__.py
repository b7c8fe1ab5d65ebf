"""Campaign reports (tables and figures from a directory of finished runs) and the on-line
evaluation's markdown. The package imports nothing on its own: ``reporting.online`` is read by
the torch-free monitor, ``reporting.build`` needs the training stack."""
