"""Generate the Python message classes Debian does not package, with ``genpy`` (install time).

Debian packages ROS 1's core messages (std, geometry, trajectory, actionlib, move_base) but not
``control_msgs``. The definitions in this folder -- ``control_msgs`` (the PR2's and TIAGo's
controller actions: PointHead, FollowJointTrajectory, GripperCommand, SingleJointPosition),
written from the interface's field names and types, so their MD5 sums match a real robot's -- and
``pycram_msgs`` (PyCRAM's own: Reach, detections, simulator-only item states and commands) are
turned into Python packages by ``genpy``, the generator ROS itself uses::

    python -m pycram.backends.ros.interfaces.generate OUTPUT_DIR

writes ``OUTPUT_DIR/control_msgs`` and ``OUTPUT_DIR/pycram_msgs``. ``scripts/install_ros.sh`` runs
it and puts ``OUTPUT_DIR`` on the virtual environment's path. Needs genpy/genmsg and the Debian
message packages importable (their ``.msg`` files are not installed, so the definitions of the
messages ours depend on are recovered from the installed classes' ``_full_text``).

An ``.action`` file is expanded into its eight messages the way ROS' ``genaction`` does (Goal,
Result, Feedback; ActionGoal, ActionResult, ActionFeedback with header and goal id / status;
Action).
"""

from __future__ import annotations

import importlib
import os
import shutil
import sys
import tempfile
from pathlib import Path

__all__ = ["generate", "PACKAGES", "DEPENDENCIES"]

HERE = Path(__file__).resolve().parent
#: The packages generated from this folder.
PACKAGES = ("control_msgs", "pycram_msgs")
#: Installed message types whose definitions (and their dependencies') the generator needs.
DEPENDENCIES = (
    "std_msgs/Header",
    "std_msgs/ColorRGBA",
    "geometry_msgs/PointStamped",
    "geometry_msgs/PoseStamped",
    "geometry_msgs/Vector3",
    "sensor_msgs/Image",
    "trajectory_msgs/JointTrajectory",
    "actionlib_msgs/GoalID",
    "actionlib_msgs/GoalStatus",
)
_SEPARATOR = "=" * 80


def _installed_definitions(types: tuple[str, ...]) -> dict[str, str]:
    """``{'pkg/Type': definition text}`` for ``types`` and everything they use, read from the
    installed Python message classes."""
    found: dict[str, str] = {}
    for full_type in types:
        package, name = full_type.split("/")
        cls = getattr(importlib.import_module(f"{package}.msg"), name)
        sections = cls._full_text.split(_SEPARATOR + "\n")
        found.setdefault(full_type, sections[0].rstrip("\n") + "\n")
        for section in sections[1:]:
            header, _, body = section.partition("\n")
            if not header.startswith("MSG: "):
                raise ValueError(f"unexpected section {header!r} in {full_type}'s definition")
            found.setdefault(header[5:].strip(), body.rstrip("\n") + "\n")
    return found


def _expand_action(name: str, text: str) -> dict[str, str]:
    """The eight message definitions of action ``name`` (as ROS' genaction writes them)."""
    parts = [p.strip("\n") for p in text.split("\n---")]
    if len(parts) != 3:
        raise ValueError(f"{name}.action needs three parts (goal, result, feedback) separated by '---'")
    goal, result, feedback = parts
    return {
        f"{name}Goal": goal + "\n",
        f"{name}Result": result + "\n",
        f"{name}Feedback": feedback + "\n",
        f"{name}ActionGoal": f"Header header\nactionlib_msgs/GoalID goal_id\n{name}Goal goal\n",
        f"{name}ActionResult": f"Header header\nactionlib_msgs/GoalStatus status\n{name}Result result\n",
        f"{name}ActionFeedback": (f"Header header\nactionlib_msgs/GoalStatus status\n{name}Feedback feedback\n"),
        f"{name}Action": (
            f"{name}ActionGoal action_goal\n{name}ActionResult action_result\n{name}ActionFeedback action_feedback\n"
        ),
    }


def _write_init(folder: Path, modules: list[str]) -> None:
    folder.mkdir(parents=True, exist_ok=True)
    lines = [f"from ._{m} import *" for m in sorted(modules)]
    (folder / "__init__.py").write_text("\n".join(lines) + "\n")


def generate(output: Path) -> list[str]:
    """Generate :data:`PACKAGES` into ``output`` (replacing earlier versions); return the
    generated types (``'control_msgs/PointHeadAction'``, ...). Raises ``RuntimeError`` naming the
    file genpy could not process."""
    from genpy.generator import MsgGenerator, SrvGenerator

    output = Path(output)
    output.mkdir(parents=True, exist_ok=True)
    generated: list[str] = []
    with tempfile.TemporaryDirectory(prefix="pycram-msgs-") as scratch:
        scratch_dir = Path(scratch)
        search_path: dict[str, list[str]] = {}
        for full_type, text in _installed_definitions(DEPENDENCIES).items():
            package, name = full_type.split("/")
            folder = scratch_dir / "deps" / package / "msg"
            folder.mkdir(parents=True, exist_ok=True)
            (folder / f"{name}.msg").write_text(text)
            search_path.setdefault(package, [str(folder)])
        sources: dict[str, tuple[dict[str, str], list[Path]]] = {}
        for package in PACKAGES:
            folder = scratch_dir / "src" / package / "msg"
            folder.mkdir(parents=True, exist_ok=True)
            messages: dict[str, str] = {}
            for path in sorted((HERE / package).glob("*.msg")):
                messages[path.stem] = path.read_text()
            for path in sorted((HERE / package).glob("*.action")):
                messages.update(_expand_action(path.stem, path.read_text()))
            for name, text in messages.items():
                (folder / f"{name}.msg").write_text(text)
            search_path[package] = [str(folder)]
            sources[package] = (messages, sorted((HERE / package).glob("*.srv")))
        staging = Path(tempfile.mkdtemp(prefix=".staging-", dir=output))
        try:
            for package, (messages, services) in sources.items():
                msg_files = [str(scratch_dir / "src" / package / "msg" / f"{n}.msg") for n in messages]
                if MsgGenerator().generate_messages(package, msg_files, str(staging / package / "msg"), search_path):
                    raise RuntimeError(f"genpy could not generate the messages of {package} (see above)")
                _write_init(staging / package / "msg", list(messages))
                generated += [f"{package}/{n}" for n in messages]
                if services:
                    if SrvGenerator().generate_messages(
                        package, [str(s) for s in services], str(staging / package / "srv"), search_path
                    ):
                        raise RuntimeError(f"genpy could not generate the services of {package}")
                    _write_init(staging / package / "srv", [s.stem for s in services])
                    generated += [f"{package}/{s.stem}" for s in services]
                (staging / package / "__init__.py").write_text("")
            for package in PACKAGES:
                target = output / package
                if target.exists():
                    shutil.rmtree(target)
                os.replace(staging / package, target)
        finally:
            shutil.rmtree(staging, ignore_errors=True)
    return generated


def main(argv: list[str]) -> int:
    if len(argv) != 1:
        print("usage: python -m pycram.backends.ros.interfaces.generate OUTPUT_DIR", file=sys.stderr)
        return 2
    types = generate(Path(argv[0]))
    print(f"generated {len(types)} ROS message/service types into {argv[0]}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
