#!/bin/sh
# Put ROS 1 (Debian's packages) at the disposal of a virtual environment: idempotent.
#
#   scripts/install_ros.sh [VENV]      (default: .venv)
#
# 1. apt-get installs the Debian packages below -- only when one of them is missing.
# 2. genpy generates the messages Debian does not package (control_msgs, pycram_msgs) from
#    pycram/backends/ros/interfaces into VENV/ros-msgs.
# 3. VENV's site-packages gets pycram-ros.pth: VENV/ros-msgs, then /usr/lib/python3/dist-packages.
#    .pth entries come AFTER the venv's own site-packages, so the venv's pinned numpy, yaml, ...
#    always win over Debian's; Debian's packages only fill in what the venv lacks (rospy, ...).
set -eu
VENV=${1:-.venv}
HERE=$(cd "$(dirname "$0")/.." && pwd)
PACKAGES="ros-core python3-rospy python3-actionlib python3-tf2-ros python3-move-base-msgs
python3-geometry-msgs python3-sensor-msgs python3-trajectory-msgs python3-genpy python3-genmsg"

missing=""
for package in $PACKAGES; do
    if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
        missing="$missing $package"
    fi
done
if [ -n "$missing" ]; then
    if ! command -v apt-get >/dev/null 2>&1; then
        echo "install_ros: WARNING: no apt-get (not Debian/Ubuntu): ROS 1 not installed; tests/ros will be skipped" >&2
        exit 0
    fi
    echo "install_ros: installing$missing"
    SUDO=""
    if [ "$(id -u)" != 0 ]; then
        command -v sudo >/dev/null 2>&1 || { echo "install_ros: need root (or sudo) for apt-get install$missing" >&2; exit 1; }
        SUDO=sudo
    fi
    $SUDO apt-get update -qq
    DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq --no-install-recommends $missing
fi

PY="$VENV/bin/python"
SITE=$("$PY" -c "import sysconfig; print(sysconfig.get_paths()['purelib'])")
MSGS=$(cd "$VENV" && pwd)/ros-msgs
printf '%s\n%s\n' "$MSGS" /usr/lib/python3/dist-packages > "$SITE/pycram-ros.pth"
PYTHONPATH="$HERE" "$PY" -m pycram.backends.ros.interfaces.generate "$MSGS"
# Check: ROS imports, and the venv's own numpy (not Debian's) comes first.
PYTHONPATH="$HERE" "$PY" - <<'PYEOF'
import importlib, sys
for name in ("rospy", "actionlib", "tf2_ros", "move_base_msgs.msg", "sensor_msgs.msg",
             "trajectory_msgs.msg", "control_msgs.msg", "pycram_msgs.msg"):
    importlib.import_module(name)
try:
    import numpy
    assert not numpy.__file__.startswith("/usr/lib/python3/"), f"Debian's numpy shadows the venv's: {numpy.__file__}"
except ImportError:
    pass
print("install_ros: ROS 1 ready for", sys.executable)
PYEOF
