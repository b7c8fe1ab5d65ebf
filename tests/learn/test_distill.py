"""Distillation: a student learns a trained teacher's soft labels, and a teacher that saw the
student's validation runs, or reads other windows, is refused in one line."""

from __future__ import annotations

import numpy as np
import pytest
import torch

from robohealth_mj.common.errors import InputError
from robohealth_mj.learn.distill import soft_label_loss
from robohealth_mj.learn.evaluation import score_checkpoint
from robohealth_mj.learn.run import train_and_evaluate as run

STUDENT = ("variant=anomaly_residual", "threads=1")  # one thread: the same bytes per seed
TINY = ("model.hidden=8", "trainer.epochs=1")


def test_soft_label_loss_is_zero_on_the_teachers_own_logits_and_grows_away_from_them():
    torch.manual_seed(0)
    teacher = {"class_logits": torch.randn(6, 7), "joint_logits": torch.randn(6, 6)}
    active = torch.tensor([True, False, True, False, True, False])
    same = soft_label_loss(teacher, teacher, active, 2.0, 1.0)
    assert float(same) == pytest.approx(0.0, abs=1e-6)
    other = {k: v + torch.randn_like(v) for k, v in teacher.items()}
    assert float(soft_label_loss(other, teacher, active, 2.0, 1.0)) > 0.01
    # the joints count only on windows the truth marks faulted
    joints_only = {"class_logits": teacher["class_logits"], "joint_logits": other["joint_logits"]}
    none_faulted = torch.zeros(6, dtype=torch.bool)
    assert float(soft_label_loss(joints_only, teacher, none_faulted, 2.0, 1.0)) == pytest.approx(
        0.0, abs=1e-6
    )


def _kl_to(teacher: np.ndarray, student: np.ndarray) -> float:
    def log_softmax(z: np.ndarray) -> np.ndarray:
        z = z - z.max(-1, keepdims=True)
        return z - np.log(np.exp(z).sum(-1, keepdims=True))

    lt, ls = log_softmax(teacher), log_softmax(student)
    return float((np.exp(lt) * (lt - ls)).sum(-1).mean())


@pytest.mark.slow
def test_a_distilled_student_ends_nearer_its_teacher_than_one_taught_by_labels(
    learnable_corpus, tiny_train_config, tmp_path
):
    def cfg(*extra: str):
        return tiny_train_config(learnable_corpus, *STUDENT, *extra)

    run(cfg("model.hidden=32", "trainer.epochs=6"), tmp_path / "teacher")
    teacher = tmp_path / "teacher" / "best.ckpt"
    student = ["model.hidden=8", "trainer.epochs=3", "trainer.patience=null"]
    run(cfg(*student), tmp_path / "labels")
    run(
        cfg(*student, f"trainer.distill.teacher={teacher}", "trainer.distill.weight=1.0",
            "trainer.distill.temperature=1.0"),
        tmp_path / "distilled",
    )  # fmt: skip
    heldout = str(learnable_corpus / "heldout")
    logits = {
        name: score_checkpoint(tmp_path / name / "best.ckpt", heldout).predictions.class_logits
        for name in ("teacher", "labels", "distilled")
    }
    assert _kl_to(logits["teacher"], logits["distilled"]) < _kl_to(
        logits["teacher"], logits["labels"]
    )


@pytest.mark.slow
def test_a_teacher_of_another_split_or_window_is_refused_in_one_line(
    tiny_corpus, tiny_train_config, tmp_path
):
    def cfg(*extra: str):
        return tiny_train_config(tiny_corpus, *STUDENT, *TINY, *extra)

    run(cfg("seed=43"), tmp_path / "t43")
    teacher = f"trainer.distill.teacher={tmp_path / 't43' / 'best.ckpt'}"
    with pytest.raises(InputError, match=r"distill\.teacher.*(normalisation|validates or tests)"):
        run(cfg("seed=42", teacher), tmp_path / "s42")
    with pytest.raises(InputError, match="reads windows of 8, the student 16"):
        run(cfg("seed=43", "window=16", teacher), tmp_path / "w16")
    with pytest.raises(InputError, match=r"trainer.distill.weight: 1.5 is not in \(0, 1\]"):
        run(cfg("seed=43", teacher, "trainer.distill.weight=1.5"), tmp_path / "w")
