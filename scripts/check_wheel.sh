#!/usr/bin/env bash
# The wheel works outside the checkout: build it (pinned `build`, isolated build environment
# with the pinned setuptools of pyproject.toml), install it into a fresh virtual environment in a
# temporary folder, and run its console script there: `pycram --version` must print the version
# of pycram/_version.py, and `pycram run` must run a small plan in block syntax. Checks that the
# wheel ships py.typed and that the installed package, not the checkout, is the one imported.
#
#   PYTHON=.venv/bin/python scripts/check_wheel.sh      (make wheel; a stage of .ci/run)
set -euo pipefail
cd "$(dirname "$0")/.."
PYTHON="${PYTHON:-.venv/bin/python}"
case "$PYTHON" in  # an absolute path: the script changes directory below
    */*) PYTHON="$(cd "$(dirname "$PYTHON")" && pwd)/$(basename "$PYTHON")" ;;
    *) PYTHON="$(command -v "$PYTHON")" ;;
esac
REPO="$PWD"
WORK="$(mktemp -d "${TMPDIR:-/tmp}/pycram-wheel.XXXXXX")"
trap 'rm -rf "$WORK"' EXIT

# Build from a copy of the sources the wheel is made of, so the checkout gets no build/ folder.
mkdir -p "$WORK/src"
cp -r pyproject.toml README.md pycram "$WORK/src/"
find "$WORK/src" -name __pycache__ -prune -exec rm -rf {} +
"$PYTHON" -m build --wheel --outdir "$WORK/dist" "$WORK/src" >"$WORK/build.log" 2>&1 \
    || { cat "$WORK/build.log" >&2; echo "check_wheel: building the wheel failed" >&2; exit 1; }
WHEEL="$(ls "$WORK"/dist/pycram-*.whl)"
echo "check_wheel: built $(basename "$WHEEL")"

"$PYTHON" - "$WHEEL" <<'PY'
import sys, zipfile
names = zipfile.ZipFile(sys.argv[1]).namelist()
missing = [n for n in ("pycram/py.typed", "pycram/_version.py", "pycram/apps/cli/__init__.py") if n not in names]
if missing:
    sys.exit(f"check_wheel: the wheel lacks {missing}")
if any(n.startswith("tests/") for n in names):
    sys.exit("check_wheel: the wheel ships tests/")
PY

# A fresh environment that knows nothing of the checkout (no PYTHONPATH, run from $WORK).
"$PYTHON" -m venv "$WORK/venv"
VPY="$WORK/venv/bin/python"
"$VPY" -m pip install --quiet --disable-pip-version-check "$WHEEL"
cd "$WORK"
unset PYTHONPATH
export HOME="$WORK/home" PYCRAM_RECORD=0
mkdir -p "$HOME"

where="$("$VPY" -c 'import pycram; print(pycram.__file__)')"
case "$where" in
    "$WORK/venv/"*) ;;
    *) echo "check_wheel: imported pycram from $where, not from the installed wheel" >&2; exit 1 ;;
esac

expected="$("$PYTHON" -c "import ast, sys; print(ast.literal_eval(open(sys.argv[1]).read().split('=')[-1].strip()))" "$REPO/pycram/_version.py")"
got="$("$WORK/venv/bin/pycram" --version)"
if [ "$got" != "pycram $expected" ]; then
    echo "check_wheel: 'pycram --version' printed '$got', expected 'pycram $expected'" >&2
    exit 1
fi
echo "check_wheel: $got"

cat >"$WORK/tiny_plan.py" <<'PLAN'
from pycram.language import State, failure_handling, par, try_in_order

log = []
errors = []
with par(errors) as both:
    log.append("left")
    log.append("right")
with try_in_order(errors) as grasp:
    if True:
        raise RuntimeError("first grasp failed")
    log.append("second grasp")
tries = 0
with failure_handling(2):
    tries += 1
    if tries < 2:
        retry()
assert both.get_value() is State.SUCCEEDED and grasp.get_value() is State.SUCCEEDED, (both, grasp)
assert sorted(log) == ["left", "right", "second grasp"] and tries == 2 and len(errors) == 1
print("tiny plan: ok")
PLAN
out="$("$WORK/venv/bin/pycram" run --no-record "$WORK/tiny_plan.py")"
if [ "$out" != "tiny plan: ok" ]; then
    echo "check_wheel: the tiny plan printed '$out'" >&2
    exit 1
fi
echo "check_wheel: pycram run tiny_plan.py: $out"
echo "check_wheel: ok"
