"""Campaign reports: every table and figure of a directory of finished runs (``build``), from
the runs' records (``tables``, ``archive``) and their figures (``figures``)."""
