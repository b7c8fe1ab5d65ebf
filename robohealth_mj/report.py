"""``python -m robohealth_mj.report DIR``: a campaign directory -> tables and figures (thesis §3).

Reads every run's ``train_summary.json`` and ``eval_*.json`` below DIR, groups them by
(graph, variant, window) and reports mean ± std over seeds: held-out (Table 6 layout), payload
probe, harness localisation and C-C0 correlation, |gamma|. Writes ``DIR/report/results.md``,
``results.csv`` and figures (or into ``--out``), and prints the tables.

With ``--archive ARCHIVE`` the finished runs' records (no checkpoints) are first copied from DIR
into ARCHIVE, a directory kept in git, and the report is built from ARCHIVE: every run archived
so far, from any machine, not only those still on this one.

    python -m robohealth_mj.report outputs/thesis_physics \
        --archive studies/thesis_physics/results/runs --out studies/thesis_physics/results

With ``--lives FILE`` (a ``lives.json`` of ``studies/wear/campaign.py``) it draws each
held-out life instead: the wearing joint's true severity, the health index with its band and the
RUL estimates against the true RUL (``--out``, default the file's directory).

    python -m robohealth_mj.report --lives outputs/lives/gbdt_last_s42/lives.json \
        --out studies/wear/results
"""

from __future__ import annotations

from robohealth_mj.common.errors import one_line_errors

with one_line_errors("report"):  # a missing extra is one line, not a traceback
    from robohealth_mj.reporting.cli import main

__all__ = ["main"]

if __name__ == "__main__":
    main()
