"""TIAGo description (one 7-DoF arm): names and numbers used by the simulated world and process modules.

Pure data, no imports; the UPPERCASE names are the keys of
:class:`pycram.world.robot_description.RobotDescription` (read them through
``pycram.world.robot_registry.robot_description("tiago")``). Angles in [rad], lengths in [m],
velocities in [m/s] / [rad/s], forces in [N].
The model is `example-robot-data`'s `tiago_no_hand.urdf` (loaded from the installed package) plus
a simple two-finger parallel gripper of our own on `arm_tool_link`, described in `GRIPPER_MODEL`,
so that its opening is measured like the PR2's.
"""

NAME = "tiago"

URDF = "robots/tiago_description/robots/tiago_no_hand.urdf"
ROOT_LINK = "base_footprint"

#: TIAGo's real base is a differential drive (two driven wheels and casters), and so is the
#: simulated one (`pycram.world.base_kinematics`): it turns on the spot, drives along its heading
#: or on arcs, never sideways; it backs up at most `max_reverse` (no laser behind it) and arrives
#: at / leaves a pose straight along its heading over `approach` where turning there would sweep
#: an arm or a carried object over the furniture. Turning on the spot costs it ~1.5x the
#: simulated time of the omnidirectional base it had until stop 41 (see docs/set-table.md).
BASE = {
    "kind": "differential",
    "max_reverse": 0.5,  # [m]
    "approach": 0.3,  # [m]
    "max_linear_velocity": 0.6,  # [m/s]
    "max_angular_velocity": 1.0,  # [rad/s]
    "linear_acceleration": 0.8,  # [m/s^2]
    "angular_acceleration": 1.5,  # [rad/s^2]
    "radius": 0.28,  # [m]
    "inscribed_radius": 0.27,  # [m] circle the footprint always covers (the round base)
    "collision_links": ("base_link", "torso_fixed_link", "torso_fixed_column_link"),
}

TORSO = {"joint": "torso_lift_joint", "range": (0.0, 0.35), "default": 0.25}  # [m]

HEAD = {
    "pan_joint": "head_1_joint",
    "tilt_joint": "head_2_joint",
    # the camera link (x: viewing direction, z: up) is read from the URDF: xtion_rgb_frame
    "fovy": 50.0,  # [deg]
    "resolution": (320, 240),  # [px]
}

ARMS = {
    "right": {
        "joints": tuple(f"arm_{i}_joint" for i in range(1, 8)),
        "tool_link": "gripper_tool_link",
        "gripper": "right",
    },
}
DEFAULT_ARM = "right"

#: Our own parallel gripper, mounted on `mount_link` (x: approach direction, y: opening direction).
GRIPPER_MODEL = {
    "mount_link": "arm_tool_link",
    "palm_size": (0.03, 0.05, 0.025),  # [m] half sizes of the palm box (x, y, z)
    "finger_size": (0.04, 0.007, 0.012),  # [m] half sizes of each finger box
    "stroke": 0.045,  # [m] travel of each finger from closed (touching) to open
    "tool_offset": 0.10,  # [m] tool frame along x from the mount link (between the finger tips)
    "mass": 0.4,  # [kg] palm mass; fingers 0.05 kg each
}

GRIPPERS = {
    "right": {
        "joint": "gripper_left_finger_joint",
        "coupled_joints": ("gripper_right_finger_joint",),
        "joint_range": (0.0, 0.045),  # [m] per finger: closed .. open
        "pad_links": ("gripper_left_finger_link", "gripper_right_finger_link"),
        "pad_offset": 0.014,  # [m] distance of the finger body frames when closed (2 x half thickness)
        "palm_link": "gripper_palm_link",
        "finger_links": ("gripper_left_finger_link", "gripper_right_finger_link"),
        "max_opening": 0.09,  # [m]
        "effort_lever": 1.0,  # prismatic fingers: effort [N] is the joint force
        "default_effort": 25.0,  # [N]
    },
}

ARM_CONFIGURATIONS = {
    "right": {
        "park": (0.20, -1.34, -0.20, 1.94, -1.57, 1.37, 0.0),
        "carry": (0.321, -0.092, -1.773, 2.215, -1.374, -0.978, -0.263),  # gripper 0.6 m ahead, 1 m high
        "zero": (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    },
}

INITIAL_CONFIGURATION = {
    **dict(zip(ARMS["right"]["joints"], ARM_CONFIGURATIONS["right"]["park"])),
    "torso_lift_joint": 0.25,
}

#: Base poses (x, y, yaw) in the simulated kitchen's map frame from which the arm reaches the cookers.
KITCHEN_BASE_POSES = {
    "cooker #2": (0.25, -0.45, -1.5708),
    "cooker #1": (-0.02, 1.75, 3.1416),
}

# --- Plan interface: numbers read by TIAGo's motion and location resolvers ---------------------------
# (pycram.robots.tiago.robot). Appended data; the entries above are used by the simulation.

#: A named arm configuration for reaching at counter height: tool 0.6 m ahead of the base,
#: 0.15 m right, 0.95 m high (torso "up"), pointing forward.
ARM_CONFIGURATIONS["right"]["pre_grasp"] = (0.277, -0.385, -1.499, 2.176, -1.794, -0.879, -0.208)

#: Carrying an object held from the top (spoon, bowl, plate): the tool pointing down, 0.6 m ahead
#: of the base, 1.07 m high (torso "up"), so that the object stays level (IK from ``carry``).
ARM_CONFIGURATIONS["right"]["carry_top"] = (0.569, 0.797, -1.351, 1.557, 0.81, -1.414, -1.17)

#: Torso heights [m] of the symbolic positions of `setting_torso`.
TORSO_POSITIONS = {"up": 0.32, "down": 0.0}

#: TIAGo has one arm and one gripper: it serves requests for either arm (thesis: '0' = left,
#: '1' = right) with them.
ARM_ALIASES = {"left": "right", "right": "right", "0": "right", "1": "right", 0: "right", 1: "right"}
GRIPPER_ALIASES = dict(ARM_ALIASES)

#: Where a point to reach lies in the base frame (x ahead [m], y left [m]) when the base stands
#: in front of it (verified in the simulated kitchen for the item spots at cooker #2 and the
#: place spot on cooker #1).
REACH_POINT_IN_BASE = {"right": (0.70, -0.15)}

#: Tool offsets of each `reaching` phase relative to the target: (back along the approach
#: direction [m], up [m]); see the PR2's description.
APPROACH_OFFSETS = {
    "pre_grasp": (0.10, 0.0),
    "grasp": (0.0, 0.0),
    "lift": (0.0, 0.10),
    "pre_place": (0.0, 0.10),
    "place": (0.0, 0.01),
    "retreat": (0.10, 0.02),
}
#: Doors (read by `pycram.actions.containers`; measured on the apartment's fridge, issue 16): its
#: parallel gripper holds a vertical handle bar by friction only (the pull runs along the
#: fingers), and the bar creeps towards the finger tips as the door follows -- about 1 deg behind
#: per 9 deg step, out of the fingers between 27 and 35 deg, sooner when pulled slowly. So it
#: pulls a door by its handle this far [rad] (20 deg: the door ends 18-19 deg open), lets go and
#: pushes the door on from inside (`DOOR_PUSH`).
DOOR_PULL_LIMIT = 0.35
#: Before closing on a door's handle bar the gripper opens this far (a fraction of its 90 mm):
#: closing from wide open, its fingers sank 2.7 mm into the 24 mm bar and then stayed there when
#: told to open (measured on the fridge; from half open they sink 0.7 mm and let go).
DOOR_GRIP_OPENING = 0.5
#: How the hand meets a door's faces when it pushes them (see `pycram.reasoning.locations.doors`). Inside:
#: the tool points along the face towards the hinge (heading pi), the side of the palm (0.05 m
#: from the tool axis, its centre 0.07 m behind the tool frame) against the face -- the back of a
#: hand sweeping a door open. Outside: the finger tips (0.04 m beyond the tool frame) into the face.
#: ``'torso'``: the torso height it pushes at (set before a standing pose is sought): with the
#: torso left down by a low drawer, the arm's way from park to the second stage of a push shut
#: crossed the fridge door and knocked it back open to 83 deg (measured).
DOOR_PUSH = {
    "inside": {"heading": 3.14159, "offset": (-0.07, 0.05), "torso": "up"},
    "outside": {"heading": -1.5708, "offset": (0.0, 0.04), "torso": "up"},
}

#: Position tolerance [m] of the tool per phase.
REACH_TOLERANCE = {"pre_grasp": 0.02, "grasp": 0.02, "pre_place": 0.02, "place": 0.02, "default": 0.01}

#: Location reasoning: a grasp pose counts as reachable only if the tool also reaches this much
#: [m] lower without touching anything (its fingers pass close above the surface; executed motions
#: pass through configurations IK
#: did not check).
GRASP_CONTACT_MARGIN = 0.005

#: How far [m] the finger tips reach beyond the tool frame along the approach (the tool's x): the
#: tool frame sits at the middle of the 8 cm fingers (`GRIPPER_MODEL`), their tips 40 mm beyond;
#: a top grasp keeps them `TOP_GRASP_CLEARANCE` above the surface the object rests on.
FINGERTIP_REACH = 0.04
#: Clearance [m] of the finger tips above the supporting surface in a top grasp.
TOP_GRASP_CLEARANCE = 0.003


# --- ROS interface: names read by `pycram.backends.ros.config` ---------------------------------------

#: TIAGo's ROS interface names: the keyword arguments of
#: `pycram.backends.ros.config.RosRobotConfig` (arms and grippers as mappings of their fields);
#: the fields not given keep that class's defaults. Its gripper's opening is the sum of its two
#: fingers' positions.
ROS = {
    "arms": {
        "right": {
            "trajectory_action": "/arm_controller/follow_joint_trajectory",
            "joint_names": ARMS["right"]["joints"],
            "reach_action": "/arm_reach",
        },
    },
    "grippers": {
        "right": {
            "action": "/gripper_controller/gripper_action",
            "opening_joints": ("gripper_left_finger_joint", "gripper_right_finger_joint"),
        },
    },
    "head_action": "/head_controller/point_head_action",
    "head_pointing_frame": "xtion_rgb_optical_frame",
    "head_pointing_axis": (0.0, 0.0, 1.0),
    "torso_action": "/torso_controller/follow_joint_trajectory",
    "torso_joint": "torso_lift_joint",
    "torso_interface": "joint_trajectory",
}
