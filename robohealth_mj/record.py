"""``python -m robohealth_mj.record``: record one labelled session (Hydra; see conf/record.yaml).

Examples::

    python -m robohealth_mj.record session.duration_s=120
    python -m robohealth_mj.record seed=7 'curriculum.payload_scales=[2.2]'
    python -m robohealth_mj.record -m seed=1,2,3,4 hydra/launcher=joblib
"""

from __future__ import annotations

from hydra.core.hydra_config import HydraConfig
from omegaconf import DictConfig

from robohealth_mj.common.config import run_tool
from robohealth_mj.common.errors import one_line_errors

with one_line_errors("record"):  # a missing extra is one line, not a traceback
    from robohealth_mj.recording.recorder import record_session, summary_text


def main(argv: list[str] | None = None) -> None:
    run_tool("record", run, argv)


def run(cfg: DictConfig) -> None:
    out_dir = cfg.session.out_dir or HydraConfig.get().runtime.output_dir
    with one_line_errors("record"):
        result = record_session(cfg, out_dir)
    print(summary_text(result), flush=True)


if __name__ == "__main__":
    main()
