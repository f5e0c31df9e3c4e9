# Sourced by the app/tests/xvfb-*.sh scripts (from the repository root,
# and inside their xvfb-run shell): what each of them needs to drive the
# real Anthesis window.

# Builds the release binary and prints its absolute path (under
# CARGO_TARGET_DIR when that is set, absolute or relative).
release_binary() {
  cargo build --release --bin anthesis >&2
  local target_dir="${CARGO_TARGET_DIR:-target}"
  case "$target_dir" in /*) ;; *) target_dir="$(pwd)/$target_dir" ;; esac
  echo "$target_dir/release/anthesis"
}

# Waits (up to 2 minutes) for the Anthesis window, then sizes it to
# 1600x1000 at the screen's corner, where the scripts' pointer positions
# are measured. Sets `window`.
wait_window() {
  window=""
  for _ in $(seq 1 240); do
    window=$(xdotool search --name "Anthesis" 2>/dev/null | head -n1 || true)
    [ -n "$window" ] && break
    sleep 0.5
  done
  [ -n "$window" ] || { echo "no Anthesis window" >&2; exit 1; }
  xdotool windowsize "$window" 1600 1000 windowmove "$window" 0 0
}

# Whether the app (process id in `app`) used more than half a core in the
# next second: its solver thread keeps it near a whole core while a run
# computes. Takes that second to answer.
busy() {
  local before; before=$(awk '{ print $14 + $15 }' /proc/$app/stat); sleep 1
  [ $(( $(awk '{ print $14 + $15 }' /proc/$app/stat) - before )) -gt 50 ]
}
