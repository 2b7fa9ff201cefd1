"""A Franka Panda on a mobile base: the Panda's URDF from example-robot-data, a base, lift column and
camera mast built from primitives around it (`COMPOSITION`), our parallel gripper instead of its
hand. Pure data: lengths [m], angles [rad], velocities [m/s, rad/s], efforts [N]."""

NAME = "mobile-panda"
URDF = "robots/panda_description/urdf/panda.urdf"  # the arm; the rest is composed around it
ROOT_LINK = "base_footprint"  # named by the composition, as are the torso and head joints below
COMPOSITION = {
    "base": {"shape": "box", "size": (0.60, 0.48), "height": 0.28},  # length, width; height
    "torso": {"position": (0.0, 0.0), "size": (0.16, 0.16, 0.25)},  # lift column: x, y; x, y, height
    "arm": {"xyz": (0.0, 0.0, 0.0)},  # the Panda's root link on the column's top
    "mast": {"position": (-0.15, 0.18), "height": 1.60},  # behind, to the left; head 1.6 m high
}
BASE = {
    "kind": "omnidirectional",
    **{"max_linear_velocity": 0.6, "max_angular_velocity": 1.0},
    **{"linear_acceleration": 0.8, "angular_acceleration": 1.5},
    **{"radius": 0.39, "inscribed_radius": 0.24},  # the 0.60 x 0.48 m box's corners, half its width
    "collision_links": ("base_link", "torso_lift_link", "mast_link"),
}
TORSO = {"joint": "torso_lift_joint", "range": (0.0, 0.45), "default": 0.3}
TORSO_POSITIONS = {"up": 0.4, "down": 0.0}
HEAD = {"pan_joint": "head_pan_joint", "tilt_joint": "head_tilt_joint", "camera_link": "head_camera_link"}
HEAD.update(fovy=50.0, resolution=(320, 240))  # [deg], [px]
# the arm's joints are read from the URDF: those from its root link to the gripper's mount
ARMS = {"arm": {"root_link": "panda_link0", "tool_link": "tool_link", "gripper": "hand"}}
#: The Panda's own hand opens 80 mm: a 70 mm cup plus the 10 mm grasp planning keeps does not fit.
GRIPPER_MODEL = {
    "mount_link": "panda_link8",  # the flange; the gripper's approach (x) across its axis, so the
    "mount_quat": (0.0, 1.0, 0.0, 0.0),  # wrist stays above a front grasp (the wrist's range)
    "replaces": ("panda_hand",),
    "palm_size": (0.03, 0.05, 0.025),  # half sizes
    "finger_size": (0.04, 0.007, 0.012),
    "tool_offset": 0.10,  # the tool frame from the flange, between the finger tips
    "mass": 0.4,
}
GRIPPERS = {
    "hand": {
        "joint": "finger_joint_left",
        "coupled_joints": ("finger_joint_right",),
        "joint_range": (0.0, 0.045),  # per finger: closed .. open
        "pad_links": ("finger_left", "finger_right"),
        "pad_offset": 0.014,
        "palm_link": "palm",
        "finger_links": ("finger_left", "finger_right"),
        "max_opening": 0.09,
        "effort_lever": 1.0,
        "default_effort": 25.0,
    },
}
ARM_ALIASES = {"arm": "arm", "left": "arm", "right": "arm", "0": "arm", "1": "arm", 0: "arm", 1: "arm"}
GRIPPER_ALIASES = {**{k: "hand" for k in ARM_ALIASES}, "hand": "hand"}
ARM_CONFIGURATIONS = {  # found by IK on the composed model, the torso "up"
    "arm": {
        "park": (-2.178, 0.222, -0.547, -2.902, -1.767, 3.407, -0.964),  # within 0.33 m, not in view
        "carry": (-0.079, -0.27, 0.082, -2.685, 0.033, 2.414, -0.024),  # tool 0.5 m ahead, 1.25 m high
        "pre_grasp": (-0.153, 0.853, 0.11, -2.048, -0.328, 2.885, 0.237),  # 0.65 m ahead, 0.95 m high
        "carry_top": (-0.13, 1.089, 0.244, -0.842, -0.04, 0.345, 0.178),  # pointing down, 1.1 m high
    },
}
INITIAL_CONFIGURATION = {
    **{f"panda_joint{i}": q for i, q in enumerate(ARM_CONFIGURATIONS["arm"]["park"], 1)},
    "torso_lift_joint": 0.3,
}
KITCHEN_BASE_POSES = {"cooker #2": (0.10, -0.50, -1.5708), "cooker #1": (-0.07, 1.90, 3.1416)}
REACH_POINT_IN_BASE = {"arm": (0.65, 0.0)}
APPROACH_OFFSETS = {"pre_grasp": (0.10, 0.0), "grasp": (0.0, 0.0), "lift": (0.0, 0.10)}
APPROACH_OFFSETS.update(pre_place=(0.0, 0.10), place=(0.0, 0.01), retreat=(0.10, 0.02))
REACH_TOLERANCE = {"pre_grasp": 0.02, "grasp": 0.02, "pre_place": 0.02, "place": 0.02, "default": 0.01}
GRASP_CONTACT_MARGIN = 0.005
FINGERTIP_REACH = 0.04  # the finger tips beyond the tool frame
TOP_GRASP_CLEARANCE = 0.003
