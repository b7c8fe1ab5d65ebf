# Sourced by the study runners after they define `run` (out_dir, then overrides: one training
# run): `parallel_runs` reads lines of "out_dir override ..." on stdin and runs them JOBS at a
# time, each logged to $ROOT/logs/<out_dir>.log by the runner's own `run`.
export -f run
export PY ROOT CORPUS
parallel_runs() {
  mkdir -p "$ROOT/logs"
  xargs -P "$JOBS" -L 1 bash -c 'run "$@"' _
}
