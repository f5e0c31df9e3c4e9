# Sourced by the app/tests/xvfb-*.sh scripts inside their xvfb-run shell:
# what each of them needs to drive the real Anthesis window.

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
