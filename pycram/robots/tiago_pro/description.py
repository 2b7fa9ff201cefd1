"""TIAGo Pro description (two 7-DoF arms, omnidirectional base): names and numbers used by the
simulated world and process modules.

Pure data, no imports; the UPPERCASE names are the keys of
:class:`pycram.world.robot_description.RobotDescription` (read them through
``pycram.world.robot_registry.robot_description("tiago-pro")``); ``_``-names are helpers. Angles in
[rad], lengths in [m], velocities in [m/s] / [rad/s], forces in [N].

The model is `example-robot-data`'s `tiago_pro.urdf` (loaded from the installed package). Its
PAL Pro grippers are replaced by the simple parallel gripper of our own that TIAGo carries
(`GRIPPER_MODEL`), mounted on each arm's tool flange: measured on the URDF's gripper (its mimic
joints coupled as the importer makes them, fingers at the URDF's joint limits), the convex hulls
of its finger tips stand 79.2 mm apart fully open and 8.4 mm apart fully closed -- the cup and
the milk carton (70 mm, plus the 10 mm margin grasp planning asks for) do not fit between them,
and the 8 mm rims of the bowl and the plate are never touched by both pads.
"""

NAME = "tiago-pro"

#: URDF path relative to the `example-robot-data` share directory.
URDF = "robots/tiago_pro_description/robots/tiago_pro.urdf"
#: Root link of the URDF; it is mounted on the simulated omnidirectional base.
ROOT_LINK = "base_footprint"

#: The omnidirectional base (four mecanum wheels in the real robot; simulated as slide x, slide y
#: and yaw joints). Footprint measured on the URDF's collision boxes of ``base_link``: 0.717 m x
#: 0.497 m (half sizes 0.3585 x 0.2485), the docking plate at its front 0.354 m ahead.
BASE = {
    "kind": "omnidirectional",
    "max_linear_velocity": 0.6,  # [m/s]
    "max_angular_velocity": 1.0,  # [rad/s]
    "linear_acceleration": 0.8,  # [m/s^2]
    "angular_acceleration": 1.5,  # [rad/s^2]
    "radius": 0.44,  # [m] circumscribed radius of the footprint (corner of the 0.717 x 0.497 m box)
    "inscribed_radius": 0.25,  # [m] circle the footprint always covers (half its 0.497 m width)
    "collision_links": ("base_link", "torso_base_link"),
}

#: The lifting torso (URDF: 0 .. 0.35 m).
TORSO = {"joint": "torso_lift_joint", "range": (0.0, 0.35), "default": 0.25}  # [m]

HEAD = {
    "pan_joint": "head_1_joint",
    "tilt_joint": "head_2_joint",
    # the camera link (x: viewing direction, z: up) is read from the URDF: head_front_camera_link
    "fovy": 50.0,  # [deg] vertical field of view
    "resolution": (320, 240),  # [px] width, height
}

#: Arms: joint names in the order of `set_arm_joints`, the tool frame (of our gripper; x: approach
#: direction, y: finger opening direction) and the gripper mounted on it.
ARMS = {
    "right": {
        "joints": tuple(f"arm_right_{i}_joint" for i in range(1, 8)),
        "tool_link": "gripper_right_tool_link",
        "gripper": "right",
    },
    "left": {
        "joints": tuple(f"arm_left_{i}_joint" for i in range(1, 8)),
        "tool_link": "gripper_left_tool_link",
        "gripper": "left",
    },
}
DEFAULT_ARM = "right"

#: Our own parallel gripper (as TIAGo's), mounted on each arm's tool flange
#: ``arm_<side>_tool_link``, whose z axis points along the forearm: `mount_quat` turns the
#: gripper's approach axis (x) onto it (-90 deg about y), its opening axis (y) stays the flange's
#: y. The URDF's own PAL Pro grippers (`replaces`, with their linkages) are taken off first.
GRIPPER_MODEL = {
    "mount_link": {"right": "arm_right_tool_link", "left": "arm_left_tool_link"},
    "mount_quat": (0.7071068, 0.0, -0.7071068, 0.0),  # (w, x, y, z)
    "replaces": ("gripper_right_base_link", "gripper_left_base_link"),
    "palm_size": (0.03, 0.05, 0.025),  # [m] half sizes of the palm box (x, y, z)
    "finger_size": (0.04, 0.007, 0.012),  # [m] half sizes of each finger box
    "stroke": 0.045,  # [m] travel of each finger from closed (touching) to open
    "tool_offset": 0.10,  # [m] tool frame along x from the mount link (between the finger tips)
    "mass": 0.4,  # [kg] palm mass; fingers 0.05 kg each
}


def _gripper(side: str) -> dict:
    return {
        "joint": f"gripper_{side}_left_finger_joint",
        "coupled_joints": (f"gripper_{side}_right_finger_joint",),
        "joint_range": (0.0, 0.045),  # [m] per finger: closed .. open
        "pad_links": (f"gripper_{side}_left_finger_link", f"gripper_{side}_right_finger_link"),
        "pad_offset": 0.014,  # [m] distance of the finger body frames when closed (2 x half thickness)
        "palm_link": f"gripper_{side}_palm_link",
        "finger_links": (f"gripper_{side}_left_finger_link", f"gripper_{side}_right_finger_link"),
        "max_opening": 0.09,  # [m]
        "effort_lever": 1.0,  # prismatic fingers: effort [N] is the joint force
        "default_effort": 25.0,  # [N]
    }


GRIPPERS = {"right": _gripper("right"), "left": _gripper("left")}

#: Named arm configurations of the right arm (joint order as in ARMS["right"]["joints"]), found
#: by IK on the model (mink on the tool site, the torso "up", the base on free floor, 30-100
#: random seeds per target; of the collision-free solutions the one whose arm stays highest ahead
#: of the base's front edge, then farthest from the joint limits); the left arm mirrors them
#: (`_mirror`: joints 1, 3, 5 and 7 negated -- checked on the model: the tool poses mirror, the
#: tool's z axis keeps its sign). As on the PR2 and the TIAGo, a tool held level has its z axis
#: up (the orientation `reaching` asks of a side grasp: the base's heading, fingers opening
#: horizontally): an earlier carry and pre_grasp had it down, so every object picked up was
#: turned upside down on the way to carry and back when put down (set-table: the milk carton
#: came down tilted and was knocked over, 5 of dev seeds 1-10).
#: The arm is long (shoulder to tool ~0.95 m) and its elbow bends only to -2.44 rad: the tool
#: comes no closer than ~0.55 m ahead of the base centre at carrying height, and only turned
#: inwards (pointing ahead, 0.6 m is the closest, with the elbow at its limit).
ARM_CONFIGURATIONS = {
    "right": {
        #: tucked: elbow down beside the torso, forearm up, the gripper upright by the shoulder;
        #: every arm link within 0.35 m of the base centre (inside the footprint's 0.44 m), none
        #: below 0.45 m with the torso down, none across the robot's middle (random search over
        #: 150,000 configurations at least 0.2 rad inside the joint limits)
        "park": (-0.209, -2.036, 2.416, -2.002, 0.483, -0.385, -1.163),
        #: the tool 0.55 m ahead (0.19 m beyond the base's front), in line with the shoulder
        #: (0.20 m right), 1.20 m high (torso "up"), level (z up), pointing 60 deg inwards; every
        #: arm link ahead of the base's front stays above 1.14 m (a counter is 0.9 m high, a milk
        #: carton on it 1.1 m), 0.44 rad inside the joint limits. The carry before (the tool 0.70
        #: m ahead, 1.02 m high) stood just short of the objects on the counter at a grasping
        #: pose: with the arm raised to carry the robot touched the milk there, and navigation
        #: refused the standing pose (goal_in_collision).
        "carry": (-2.191, -1.675, 0.897, -2.003, 0.635, -0.616, -1.508),
        "zero": (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    },
}


def _mirror(q: tuple) -> tuple:
    return tuple(-v if i in (0, 2, 4, 6) else v for i, v in enumerate(q))


#: Reaching at counter height (an IK seed for grasps, `reaching`'s orientation): the tool 0.75 m
#: ahead of the base, in line with the shoulder, 0.95 m high (torso "up"), pointing forward, z
#: up, fingers opening horizontally; 0.31 rad inside the joint limits (the most of 38 solutions).
ARM_CONFIGURATIONS["right"]["pre_grasp"] = (-1.998, -0.969, 0.548, -2.133, -0.093, 0.938, -1.451)
#: Carrying an object held from the top (bowl, plate): the tool pointing down, its fingers
#: opening across the base's heading (the orientation of a top grasp with the base's heading),
#: 0.55 m ahead of the base, in line with the shoulder, 1.15 m high (torso "up"), so that the
#: object stays level; the arm ahead of the base's front above 1.11 m, 0.40 rad inside the limits.
ARM_CONFIGURATIONS["right"]["carry_top"] = (-3.117, -1.976, 0.507, -1.591, -0.061, -1.481, 0.15)

ARM_CONFIGURATIONS["left"] = {name: _mirror(q) for name, q in ARM_CONFIGURATIONS["right"].items()}

#: Initial joint positions when a world is created (arms parked, torso at its default).
INITIAL_CONFIGURATION = {
    **dict(zip(ARMS["right"]["joints"], ARM_CONFIGURATIONS["right"]["park"])),
    **dict(zip(ARMS["left"]["joints"], ARM_CONFIGURATIONS["left"]["park"])),
    "torso_lift_joint": 0.25,
}

#: Base poses (x, y, yaw) in the simulated kitchen's map frame from which the right arm reaches
#: the cookers.
KITCHEN_BASE_POSES = {
    "cooker #2": (0.30, -0.42, -1.5708),
    "cooker #1": (0.0, 1.70, 3.1416),
}

#: Torso heights [m] of the symbolic positions of `setting_torso`.
TORSO_POSITIONS = {"up": 0.32, "down": 0.0}

#: Arm / gripper names accepted in designators -> the physical arm / gripper (thesis: '0' = left,
#: '1' = right).
ARM_ALIASES = {"left": "left", "right": "right", "0": "left", "1": "right", 0: "left", 1: "right"}
GRIPPER_ALIASES = dict(ARM_ALIASES)

#: Where a point to reach lies in the base frame (x ahead [m], y left [m]) when the base stands in
#: front of it, per arm.
REACH_POINT_IN_BASE = {"right": (0.75, -0.2), "left": (0.75, 0.2)}

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
#: Position tolerance [m] of the tool per phase.
REACH_TOLERANCE = {"pre_grasp": 0.02, "grasp": 0.02, "pre_place": 0.02, "place": 0.02, "default": 0.01}

#: Location reasoning: a grasp pose counts as reachable only if the tool also reaches this much
#: [m] lower without touching anything.
GRASP_CONTACT_MARGIN = 0.005

#: How far [m] the finger tips reach beyond the tool frame along the approach (the tool's x): the
#: tool frame sits at the middle of the 8 cm fingers (`GRIPPER_MODEL`), their tips 40 mm beyond.
FINGERTIP_REACH = 0.04
#: Clearance [m] of the finger tips above the supporting surface in a top grasp.
TOP_GRASP_CLEARANCE = 0.003
