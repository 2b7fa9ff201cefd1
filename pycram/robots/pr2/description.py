"""PR2 description: names and numbers of the PR2 as used by the simulated world and process modules.

Pure data, no imports: every constant here can be read by resolvers and process modules without
loading a simulator. The UPPERCASE names are the keys of
:class:`pycram.world.robot_description.RobotDescription` (which validates them; read them through
``pycram.world.robot_registry.robot_description("pr2")``); ``_``-names are helpers. Angles in
[rad], lengths in [m], velocities in [m/s] / [rad/s], forces in [N].
The model is `example-robot-data`'s PR2 URDF (loaded from the installed package, never copied).
"""

NAME = "pr2"

#: URDF path relative to the `example-robot-data` share directory.
URDF = "robots/pr2_description/urdf/pr2.urdf"
#: Root link of the URDF; it is mounted on an omnidirectional base (slide x, slide y, hinge yaw).
ROOT_LINK = "base_footprint"

#: Base limits and the links that count as "the base" when checking for collisions while driving.
BASE = {
    "max_linear_velocity": 0.6,  # [m/s]
    "max_angular_velocity": 1.0,  # [rad/s]
    "linear_acceleration": 0.8,  # [m/s^2]
    "angular_acceleration": 1.5,  # [rad/s^2]
    "radius": 0.47,  # [m] circumscribed radius of the footprint (corner of the 0.67 m square)
    "inscribed_radius": 0.335,  # [m] circle the footprint always covers (half the 0.67 m square)
    "collision_links": ("base_link", "torso_lift_link"),
}

TORSO = {"joint": "torso_lift_joint", "range": (0.0, 0.31), "default": 0.2}  # [m]

HEAD = {
    "pan_joint": "head_pan_joint",
    "tilt_joint": "head_tilt_joint",
    #: link whose +x axis is the camera's viewing direction and +z its up direction: stated, the
    #: URDF's head has several cameras (high_def_frame, the stereo pairs) and none is the colour one
    "camera_link": "high_def_frame",
    "fovy": 55.0,  # [deg] vertical field of view
    "resolution": (320, 240),  # [px] width, height
}

_ARM_JOINT_SUFFIXES = (
    "shoulder_pan_joint",
    "shoulder_lift_joint",
    "upper_arm_roll_joint",
    "elbow_flex_joint",
    "forearm_roll_joint",
    "wrist_flex_joint",
    "wrist_roll_joint",
)

#: Arms: joint names in the order of the thesis' `set_arm_joints`, the tool frame (x: approach
#: direction, y: finger opening direction) and the gripper mounted on it.
ARMS = {
    "right": {
        "joints": tuple("r_" + s for s in _ARM_JOINT_SUFFIXES),
        "tool_link": "r_gripper_tool_frame",
        "gripper": "right",
    },
    "left": {
        "joints": tuple("l_" + s for s in _ARM_JOINT_SUFFIXES),
        "tool_link": "l_gripper_tool_frame",
        "gripper": "left",
    },
}
DEFAULT_ARM = "right"


def _gripper(p: str) -> dict:
    return {
        #: the actuated joint; the others follow it (URDF mimic) with factor 1
        "joint": f"{p}_gripper_l_finger_joint",
        "coupled_joints": (
            f"{p}_gripper_r_finger_joint",
            f"{p}_gripper_l_finger_tip_joint",
            f"{p}_gripper_r_finger_tip_joint",
        ),
        "joint_range": (0.0, 0.548),  # [rad] closed .. open
        #: the opening is the distance between these two links minus `pad_offset`
        "pad_links": (f"{p}_gripper_l_finger_tip_link", f"{p}_gripper_r_finger_tip_link"),
        "pad_offset": 0.0299,  # [m] link distance when fully closed
        "palm_link": f"{p}_gripper_palm_link",
        "finger_links": (
            f"{p}_gripper_l_finger_tip_link",
            f"{p}_gripper_r_finger_tip_link",
        ),
        "max_opening": 0.09,  # [m]
        "effort_lever": 0.06,  # [m] effort [N] at the finger tips x lever = joint torque [Nm]
        "default_effort": 25.0,  # [N]
    }


GRIPPERS = {"right": _gripper("r"), "left": _gripper("l")}

#: Named arm configurations (joint order as in ARMS[arm]["joints"]).
ARM_CONFIGURATIONS = {
    "right": {
        "park": (-1.712, -0.256, -1.463, -2.12, 1.766, -0.07, 0.051),
        "carry": (-0.571, -0.524, -2.081, -2.019, 3.252, -1.27, -0.893),  # gripper 0.6 m ahead, 1 m high
        "zero": (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    },
    "left": {
        "park": (1.712, -0.256, 1.463, -2.12, -1.766, -0.07, -0.051),
        "carry": (0.571, -0.524, 2.081, -2.019, -3.252, -1.27, 0.893),
        "zero": (0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0),
    },
}

#: Initial joint positions when a world is created (arms parked, torso up, head straight).
INITIAL_CONFIGURATION = {
    **dict(zip(ARMS["right"]["joints"], ARM_CONFIGURATIONS["right"]["park"])),
    **dict(zip(ARMS["left"]["joints"], ARM_CONFIGURATIONS["left"]["park"])),
    "torso_lift_joint": 0.2,
}

#: Base poses (x [m], y [m], yaw [rad]) in the simulated kitchen's map frame from which the right
#: arm reaches the cooker centres comfortably (shoulder in line with the cooker, ~0.65 m away).
#: The thesis (ch. 4) used (0.1, -0.6, -pi/2) and (-0.1, 1.9, pi) in its lab kitchen.
KITCHEN_BASE_POSES = {
    "cooker #2": (0.29, -0.55, -1.5708),
    "cooker #1": (-0.12, 1.71, 3.1416),
}

# --- Plan interface: numbers read by the PR2's motion and location resolvers ------------------------
# (pycram.robots.pr2.robot). Appended data; the entries above are used by the simulation.

#: A named arm configuration for reaching at counter height: tool 0.5 m ahead of the base, in line
#: with the shoulder, 0.95 m high (torso "up"), pointing forward.
ARM_CONFIGURATIONS["right"]["pre_grasp"] = (-0.566, -0.147, -2.211, -2.272, 2.914, -1.721, -0.982)
ARM_CONFIGURATIONS["left"]["pre_grasp"] = (0.566, -0.137, 2.215, -2.268, -2.905, -1.723, 0.984)

#: Carrying an object held from the top (spoon, bowl, plate): the tool pointing down, 0.6 m ahead
#: of the base, 1.13 m high (torso "up"), so that the object stays level (IK from ``carry``).
ARM_CONFIGURATIONS["right"]["carry_top"] = (-0.462, -0.524, -1.701, -1.13, 5.243, -1.685, -2.477)
ARM_CONFIGURATIONS["left"]["carry_top"] = (0.462, -0.524, 1.701, -1.13, -5.244, -1.684, 2.478)

#: Torso heights [m] of the symbolic positions of `setting_torso`.
TORSO_POSITIONS = {"up": 0.28, "down": 0.0}

#: Arm / gripper names accepted in designators -> the physical arm / gripper (thesis: '0' = left,
#: '1' = right).
ARM_ALIASES = {"left": "left", "right": "right", "0": "left", "1": "right", 0: "left", 1: "right"}
GRIPPER_ALIASES = dict(ARM_ALIASES)

#: Where a point to reach lies in the base frame (x ahead [m], y left [m]) when the base stands
#: in front of it, per arm: in line with that arm's shoulder, 0.65 m ahead (verified in the
#: simulated kitchen for the three item spots at cooker #2 and the place spot on cooker #1).
REACH_POINT_IN_BASE = {"right": (0.65, -0.19), "left": (0.65, 0.19)}

#: Tool offsets of each `reaching` phase relative to the target: (back along the approach
#: direction [m], up [m]). The approach direction is the base's heading (the base faces the
#: counter); the tool points along it with its fingers opening horizontally.
APPROACH_OFFSETS = {
    "pre_grasp": (0.10, 0.0),
    "grasp": (0.0, 0.0),
    "lift": (0.0, 0.10),
    "pre_place": (0.0, 0.10),
    "place": (0.0, 0.01),
    "retreat": (0.10, 0.02),
}
#: Position tolerance [m] of the tool per phase (grasping pushes against the item a little).
REACH_TOLERANCE = {"pre_grasp": 0.02, "grasp": 0.02, "pre_place": 0.02, "place": 0.02, "default": 0.01}

#: Location reasoning: a grasp pose counts as reachable only if the tool also reaches this much
#: [m] lower without touching anything (its forearm passes low over the furniture's edge; executed
#: motions pass through configurations IK
#: did not check).
GRASP_CONTACT_MARGIN = 0.015

#: How the hand meets a door's outside face when it pushes a door shut (see
#: `pycram.reasoning.locations.doors`; used when the door was not opened by its handle from a pose the
#: robot remembers, e.g. after a failed opening): the finger tips (at the tool frame) into the
#: face, the gripper open (with it closed or half open, location reasoning found no standing pose
#: for the push from 30 deg to shut: 100 candidates, mostly the approach out of reach).
DOOR_PUSH = {"outside": {"heading": -1.5708, "offset": (0.0, 0.01), "gripper": 1.0}}

#: How far [m] the finger tips reach beyond the tool frame along the approach (the tool's x):
#: a top grasp keeps them `TOP_GRASP_CLEARANCE` above the surface the object rests on (measured
#: on the model: the finger tip links' collision hulls end 15 mm past `*_gripper_tool_frame`).
FINGERTIP_REACH = 0.015
#: Clearance [m] of the finger tips above the supporting surface in a top grasp.
TOP_GRASP_CLEARANCE = 0.003


# --- ROS interface: names read by `pycram.backends.ros.config` ---------------------------------------

#: The real PR2's ROS interface names (thesis ch. 4.1, ``control.py``): the keyword arguments of
#: `pycram.backends.ros.config.RosRobotConfig` (arms and grippers as mappings of their fields);
#: the fields not given keep that class's defaults. The PR2 publishes each gripper's gap as one
#: joint (``r_gripper_joint``).
ROS = {
    "arms": {
        "right": {
            "trajectory_action": "/r_arm_controller/follow_joint_trajectory",
            "joint_names": ARMS["right"]["joints"],
            "reach_action": "/r_arm_reach",
        },
        "left": {
            "trajectory_action": "/l_arm_controller/follow_joint_trajectory",
            "joint_names": ARMS["left"]["joints"],
            "reach_action": "/l_arm_reach",
        },
    },
    "grippers": {
        "right": {"action": "/r_gripper_controller/gripper_action", "opening_joints": ("r_gripper_joint",)},
        "left": {"action": "/l_gripper_controller/gripper_action", "opening_joints": ("l_gripper_joint",)},
    },
    "head_action": "/head_traj_controller/point_head_action",
    "head_pointing_frame": "high_def_frame",
    "head_pointing_axis": (1.0, 0.0, 0.0),
    "torso_action": "/torso_controller/position_joint_action",
    "torso_joint": "torso_lift_joint",
    "torso_interface": "single_joint_position",
}
