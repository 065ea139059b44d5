#!/usr/bin/env bash
# A user's trial of the window on a virtual display: open a mesh, let the window build its DAG,
# orbit, move the pixel threshold, colour by cluster; screenshots of each step go to OUT/.
#   apt-get install -y xvfb xdotool imagemagick mesa-vulkan-drivers libvulkan1
#   cargo build --release && bash benches/window_trial.sh .dev/scan-4m.ply /tmp/trial
# Prints, per step, what the screen showed: during the orbit, how many distinct pictures the
# screen showed in the screenshots taken (a frozen window shows one). MESHSLIM names the binary;
# VIEW_ARGS adds to the view command ("--auto-dag 0" draws the mesh whole throughout).
set -euo pipefail
mesh=${1:?usage: window_trial.sh MESH OUT_DIR}
out=${2:?usage: window_trial.sh MESH OUT_DIR}
bin=${MESHSLIM:-target/release/meshslim}
wait_dag=${WAIT_DAG:-30}
mkdir -p "$out"
export DISPLAY=${TRIAL_DISPLAY:-:97}
Xvfb "$DISPLAY" -screen 0 1280x800x24 >"$out/xvfb.log" 2>&1 &
xvfb=$!
trap 'kill $view $xvfb 2>/dev/null || true' EXIT
sleep 1
"$bin" view "$mesh" --size 1280x800 ${VIEW_ARGS:-} >"$out/view.log" 2>&1 &
view=$!
shot() { import -window root "$out/$1.png"; }
sleep "$wait_dag"
shot 1-opened
# The orbit: a left drag across the 3D view over about 2 s, a screenshot every fourth step.
xdotool mousemove 800 400 mousedown 1
start=$(date +%s.%N)
for i in $(seq 1 24); do
    xdotool mousemove $((800 + i * 12)) 400
    sleep 0.08
    if ((i % 3 == 0)); then shot "2-orbit-$i"; fi
done
xdotool mouseup 1
echo "orbit: $(echo "$(date +%s.%N) - $start" | bc) s, distinct pictures in 8 screenshots:" \
    "$(md5sum "$out"/2-orbit-*.png | cut -d' ' -f1 | sort -u | wc -l)"
sleep 1
shot 3-after-orbit
# The pixel threshold: the panel's "error (pixels)" slider dragged from 1 px to its end, 16 px.
# The window draws on input only, so the drag is spread over several frames (one burst of
# events is one frame, in which egui sees the press and the release but no drag).
xdotool mousemove 72 485 mousedown 1
for x in 90 110 130 150 170 190 200; do sleep 0.1; xdotool mousemove "$x" 485; done
sleep 0.1
xdotool mouseup 1
sleep 1
shot 4-sixteen-pixels
# Key 7 colours the cut by cluster (the window takes the keyboard first: Xvfb has no window
# manager to give it).
xdotool windowfocus --sync "$(xdotool search --name '^meshslim$' | head -1)"
xdotool mousemove 800 400 key 7
sleep 1
shot 5-clusters
echo "screenshots in $out"
