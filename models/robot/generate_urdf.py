#!/usr/bin/env python3
"""Writes agrisim_robot.urdf next to this script (run it after editing; the URDF is checked in).

Why generated: the two arms and grippers are the same Panda-like chain with a prefix, and the
four wheel modules differ only by position; writing them once avoids copy-paste drift.

Sources of figures:
- Base: 4-wheel-steering, wheel base 1.0 m, track 0.8 m, wheel radius 0.1 m, steer +-90 deg,
  steer rate 3 rad/s, wheel speed 15 rad/s (fmus/lib/chassis/src/ports.rs defaults).
- Lift: prismatic 0..0.8 m, 0.2 m/s; carriage centre 0.45 m above the floor at 0
  (fmus/lift/src/lib.rs: position_max, velocity_max, base_height).
- Arms: Franka Emika Panda kinematic parameters (modified DH, Craig convention) and joint
  position/velocity/torque limits as published by Franka Emika in the FCI documentation,
  "Robot and interface specifications" (frankaemika.github.io/docs/control_parameters.html).
- Panda link masses: Gaz, Cognetti, Oliva, Robuffo Giordano, De Luca, "Dynamic Identification
  of the Franka Emika Panda Robot With Retrieval of Feasible Parameters Using Penalty-Based
  Optimization", IEEE RA-L 4(4), 2019. Centres of mass and inertia tensors here are NOT the
  identified ones: they are estimates from the collision cylinders (solid-cylinder formulas).
- Gripper: Franka Hand, fingers 0..0.04 m each (80 mm stroke), hand mass 0.73 kg (datasheet);
  finger masses are estimates.
- Lidar and IMU at base_link + z 1.0 m (fmus/lidar and fmus/imu mount defaults); the IMU is
  co-located with the lidar because the Livox Mid-360 carries its own IMU.
"""
import math, os

PI = math.pi
out = []
def w(s=""):
    out.append(s)

def f(x):
    s = repr(round(x, 15))
    return "0" if s in ("0.0", "-0.0") else s

def v3(a):
    return " ".join(f(x) for x in a)

def origin(xyz=(0, 0, 0), rpy=(0, 0, 0)):
    return f'<origin xyz="{v3(xyz)}" rpy="{v3(rpy)}"/>'

def geom(g):
    kind = g[0]
    if kind == "box":
        return f'<box size="{v3(g[1])}"/>'
    if kind == "cyl":
        return f'<cylinder radius="{f(g[1])}" length="{f(g[2])}"/>'
    if kind == "sphere":
        return f'<sphere radius="{f(g[1])}"/>'
    raise ValueError(kind)

def inertia_of(g, m):
    """Solid-primitive inertia about its own centre, in its own frame (diagonal)."""
    kind = g[0]
    if kind == "box":
        x, y, z = g[1]
        return (m * (y*y + z*z) / 12, m * (x*x + z*z) / 12, m * (x*x + y*y) / 12)
    if kind == "cyl":
        r, h = g[1], g[2]
        a = m * (3*r*r + h*h) / 12
        return (a, a, m * r * r / 2)
    if kind == "sphere":
        a = 2 * m * g[1] ** 2 / 5
        return (a, a, a)

def link(name, collisions=(), visuals=None, mass=None, inertial_from=None, material="grey", comment=None):
    """collisions/visuals: lists of (geometry, xyz, rpy). The inertial is a solid version of
    `inertial_from` (default: the first collision primitive) with its pose, so it is always
    physically consistent (triangle inequality holds)."""
    if comment:
        w(f"  <!-- {comment} -->")
    w(f'  <link name="{name}">')
    if mass is not None:
        g, xyz, rpy = inertial_from if inertial_from else collisions[0]
        ixx, iyy, izz = inertia_of(g, mass)
        w("    <inertial>")
        w(f"      {origin(xyz, rpy)}")
        w(f'      <mass value="{f(mass)}"/>')
        w(f'      <inertia ixx="{f(ixx)}" ixy="0" ixz="0" iyy="{f(iyy)}" iyz="0" izz="{f(izz)}"/>')
        w("    </inertial>")
    for g, xyz, rpy in (visuals if visuals is not None else collisions):
        w("    <visual>")
        w(f"      {origin(xyz, rpy)}")
        w(f"      <geometry>{geom(g)}</geometry>")
        w(f'      <material name="{material}"/>')
        w("    </visual>")
    for i, (g, xyz, rpy) in enumerate(collisions):
        w("    <collision>")
        w(f"      {origin(xyz, rpy)}")
        w(f"      <geometry>{geom(g)}</geometry>")
        w("    </collision>")
    w("  </link>")

def joint(name, kind, parent, child, xyz=(0, 0, 0), rpy=(0, 0, 0), axis=None, limit=None):
    w(f'  <joint name="{name}" type="{kind}">')
    w(f'    <parent link="{parent}"/>')
    w(f'    <child link="{child}"/>')
    w(f"    {origin(xyz, rpy)}")
    if axis:
        w(f'    <axis xyz="{v3(axis)}"/>')
    if limit:
        lo, hi, eff, vel = limit
        lim = f'effort="{f(eff)}" velocity="{f(vel)}"'
        if lo is not None:
            lim = f'lower="{f(lo)}" upper="{f(hi)}" ' + lim
        w(f"    <limit {lim}/>")
    w("  </joint>")

# ---------------------------------------------------------------- figures
WHEEL_BASE, TRACK, WHEEL_R, WHEEL_W = 1.0, 0.8, 0.1, 0.08
BODY = (1.2, 0.9, 0.2)
BODY_Z = 0.32            # body box 0.22..0.42 m: clears the 0.2 m wheel tops
DECK = BODY_Z + BODY[2] / 2
LIFT_X = 0.2             # carriage centre on base_link x
LIFT_Z0 = 0.45           # carriage centre above the floor at lift 0 (lift base_height)
ARM_Y = 0.25             # arm bases left/right of the carriage centre
CARRIAGE = (0.2, 0.7, 0.05)

# Franka Panda modified DH (a, d, alpha) per joint 1..7, flange d = 0.107 m.
PANDA_DH = [(0, 0.333, 0), (0, 0, -PI/2), (0, 0.316, PI/2), (0.0825, 0, PI/2),
            (-0.0825, 0.384, -PI/2), (0, 0, PI/2), (0.088, 0, PI/2)]
PANDA_FLANGE_D = 0.107
PANDA_Q_MIN = [-2.8973, -1.7628, -2.8973, -3.0718, -2.8973, -0.0175, -2.8973]
PANDA_Q_MAX = [2.8973, 1.7628, 2.8973, -0.0698, 2.8973, 3.7525, 2.8973]
PANDA_DQ_MAX = [2.1750, 2.1750, 2.1750, 2.1750, 2.6100, 2.6100, 2.6100]
PANDA_TAU_MAX = [87, 87, 87, 87, 12, 12, 12]
# Gaz et al. 2019 identified masses, links 1..7 (kg); link0 is an estimate.
PANDA_MASS = [4.970684, 0.646926, 3.228604, 3.587895, 1.225946, 1.666555, 0.735522]
# Collision cylinders per link i (0..7) in the link's own frame: (radius, length, xyz, rpy),
# sized to envelope the Panda casings (estimates from the published dimension drawing).
PANDA_COLL = [
    (0.06, 0.14, (0, 0, 0.07), (0, 0, 0)),          # link0: base flange
    (0.06, 0.20, (0, 0, -0.13), (0, 0, 0)),         # link1: column below joint 2
    (0.06, 0.12, (0, 0, 0), (0, 0, 0)),             # link2: shoulder around joint 2 axis
    (0.06, 0.15, (0, 0, -0.075), (0, 0, 0)),        # link3: upper arm below joint 4
    (0.06, 0.12, (0, 0, 0), (0, 0, 0)),             # link4: elbow around joint 4 axis
    (0.06, 0.20, (0, 0, -0.16), (0, 0, 0)),         # link5: forearm
    (0.05, 0.08, (0, 0, 0), (0, 0, 0)),             # link6: wrist around joint 6 axis
    (0.04, 0.10, (0, 0, 0.06), (0, 0, 0)),          # link7: wrist flange
]

w('<?xml version="1.0"?>')
w("<!-- GENERATED by models/robot/generate_urdf.py: edit that and re-run. -->")
w("<!-- agrisim mobile dual-arm greenhouse harvesting robot. Frames: REP 103 (x forward,")
w("     y left, z up), base_link per REP 105 at the floor below the base centre. -->")
w('<robot name="agrisim_robot">')
for name, rgba in [("grey", "0.6 0.6 0.6 1"), ("dark", "0.2 0.2 0.2 1"), ("white", "0.95 0.95 0.95 1"),
                   ("green", "0.2 0.6 0.3 1"), ("orange", "0.9 0.5 0.1 1")]:
    w(f'  <material name="{name}"><color rgba="{rgba}"/></material>')

# ---------------------------------------------------------------- base
link("base_link",
     collisions=[(("box", BODY), (0, 0, BODY_Z), (0, 0, 0))],
     visuals=[(("box", (1.18, 0.88, 0.2)), (0, 0, BODY_Z), (0, 0, 0))],
     mass=120.0, material="green",
     comment="Chassis body 1.2 x 0.9 m; mass 120 kg is an estimate (battery, frame, drives).")
for tag, sx, sy in [("front_left", 1, 1), ("front_right", 1, -1), ("rear_left", -1, 1), ("rear_right", -1, -1)]:
    steer = f"{tag}_steer_link"
    wheel = f"{tag}_wheel_link"
    link(steer, collisions=[(("cyl", 0.03, 0.08), (0, 0, 0.08), (0, 0, 0))],
         visuals=[(("cyl", 0.025, 0.08), (0, 0, 0.08), (0, 0, 0))], mass=2.0, material="dark")
    joint(f"{tag}_steer_joint", "revolute", "base_link", steer,
          xyz=(sx * WHEEL_BASE / 2, sy * TRACK / 2, WHEEL_R), axis=(0, 0, 1),
          limit=(-PI/2, PI/2, 50.0, 3.0))
    link(wheel, collisions=[(("cyl", WHEEL_R, WHEEL_W), (0, 0, 0), (PI/2, 0, 0))],
         visuals=[(("cyl", WHEEL_R, WHEEL_W - 0.01), (0, 0, 0), (PI/2, 0, 0))], mass=3.0, material="dark")
    joint(f"{tag}_drive_joint", "continuous", steer, wheel, axis=(0, 1, 0),
          limit=(None, None, 40.0, 15.0))

# Rear enclosure (electronics housing) and the harvest box on it.
ENC = (0.5, 0.9, 0.3)
ENC_X = -0.35
link("rear_enclosure_link", collisions=[(("box", ENC), (0, 0, ENC[2] / 2), (0, 0, 0))],
     visuals=[(("box", (0.49, 0.88, 0.3)), (0, 0, ENC[2] / 2), (0, 0, 0))], mass=25.0, material="white",
     comment="Rear enclosure on the deck; mass is an estimate.")
joint("rear_enclosure_joint", "fixed", "base_link", "rear_enclosure_link", xyz=(ENC_X, 0, DECK))
BOX = (0.4, 0.6, 0.25)   # outer size of the open harvest crate
T = 0.01                 # wall and bottom thickness
bx, by, bz = BOX
box_coll = [
    (("box", (bx, by, T)), (0, 0, T / 2), (0, 0, 0)),                                # bottom
    (("box", (T, by, bz)), (bx / 2 - T / 2, 0, bz / 2), (0, 0, 0)),                  # front wall
    (("box", (T, by, bz)), (-bx / 2 + T / 2, 0, bz / 2), (0, 0, 0)),                 # rear wall
    (("box", (bx - 2 * T, T, bz)), (0, by / 2 - T / 2, bz / 2), (0, 0, 0)),          # left wall
    (("box", (bx - 2 * T, T, bz)), (0, -by / 2 + T / 2, bz / 2), (0, 0, 0)),         # right wall
]
link("harvest_box_link", collisions=box_coll, mass=1.5, inertial_from=(("box", BOX), (0, 0, bz / 2), (0, 0, 0)),
     material="orange", comment="Open harvest crate: bottom + 4 walls, each its own collision box.")
joint("harvest_box_joint", "fixed", "rear_enclosure_link", "harvest_box_link", xyz=(0, 0, ENC[2]))
w("  <!-- Inside bottom centre of the crate: where placed fruit rests. -->")
w('  <link name="harvest_box"/>')
joint("harvest_box_frame_joint", "fixed", "harvest_box_link", "harvest_box", xyz=(0, 0, T))

# Sensor post with lidar and IMU.
link("sensor_post_link", collisions=[(("cyl", 0.02, 1.0 - 0.0325 - DECK), (0, 0, (1.0 - 0.0325 - DECK) / 2), (0, 0, 0))],
     mass=1.0, material="grey", comment="Post carrying the lidar; mass is an estimate.")
joint("sensor_post_joint", "fixed", "base_link", "sensor_post_link", xyz=(0, 0, DECK))
link("lidar_link", collisions=[(("cyl", 0.0325, 0.065), (0, 0, 0), (0, 0, 0))], mass=0.265, material="dark",
     comment="Livox Mid-360 (65 mm x 65 mm, 265 g per its user manual); at base_link + z 1.0 m as the Lidar FMU default.")
joint("lidar_joint", "fixed", "base_link", "lidar_link", xyz=(0, 0, 1.0))
w("  <!-- IMU: base_link + z 1.0 m as the Imu FMU default (the Mid-360's built-in IMU). -->")
w('  <link name="imu_link"/>')
joint("imu_joint", "fixed", "base_link", "imu_link", xyz=(0, 0, 1.0))

# ---------------------------------------------------------------- lift
MAST_H = 0.9
link("lift_mast_link",
     collisions=[(("box", (0.04, 0.04, MAST_H)), (0, y, MAST_H / 2), (0, 0, 0)) for y in (0.15, -0.15)],
     mass=15.0, inertial_from=(("box", (0.04, 0.34, MAST_H)), (0, 0, MAST_H / 2), (0, 0, 0)), material="grey",
     comment="Two lift rails on the deck; mass is an estimate.")
joint("lift_mast_joint", "fixed", "base_link", "lift_mast_link", xyz=(LIFT_X - 0.12, 0, DECK))
link("lift_link", collisions=[(("box", CARRIAGE), (0, 0, 0), (0, 0, 0))], mass=8.0, material="grey",
     comment="Lift carriage, origin at its centre; carries both arms and the camera. Mass is an estimate.")
joint("lift_joint", "prismatic", "base_link", "lift_link", xyz=(LIFT_X, 0, LIFT_Z0), axis=(0, 0, 1),
      limit=(0.0, 0.8, 2000.0, 0.2))

# Camera on a short post at the carriage front, looking forward.
link("camera_link", collisions=[(("box", (0.03, 0.09, 0.025)), (0, 0, 0), (0, 0, 0))], mass=0.072, material="dark",
     comment="RGB-D camera body (RealSense D435-sized, 90 x 25 x 25 mm, 72 g), REP 103 axes.")
joint("camera_joint", "fixed", "lift_link", "camera_link", xyz=(CARRIAGE[0] / 2 + 0.02, 0, 0.15))
w("  <!-- Optical frame: z forward, x right, y down (REP 103 camera convention). -->")
w('  <link name="camera_color_optical_frame"/>')
joint("camera_color_optical_joint", "fixed", "camera_link", "camera_color_optical_frame", rpy=(-PI/2, 0, -PI/2))

# ---------------------------------------------------------------- arms + grippers
def arm(side, y):
    p = f"{side}_"
    c = PANDA_COLL[0]
    link(p + "link0", collisions=[(("cyl", c[0], c[1]), c[2], c[3])], mass=2.9, material="white",
         comment=f"{side} arm: Panda-like 7-DoF. link0 mass is an estimate; links 1-7 masses from Gaz et al. 2019.")
    joint(p + "arm_mount_joint", "fixed", "lift_link", p + "link0", xyz=(0, y, CARRIAGE[2] / 2))
    parent = p + "link0"
    for i, (a, d, alpha) in enumerate(PANDA_DH):
        c = PANDA_COLL[i + 1]
        name = f"{p}link{i + 1}"
        link(name, collisions=[(("cyl", c[0], c[1]), c[2], c[3])], mass=PANDA_MASS[i], material="white")
        # Modified DH: RotX(alpha) TransX(a) RotZ(q) TransZ(d) == origin(a, -d sin alpha, d cos alpha; rpy alpha).
        joint(f"{p}joint{i + 1}", "revolute", parent, name,
              xyz=(a, -d * math.sin(alpha), d * math.cos(alpha)), rpy=(alpha, 0, 0), axis=(0, 0, 1),
              limit=(PANDA_Q_MIN[i], PANDA_Q_MAX[i], PANDA_TAU_MAX[i], PANDA_DQ_MAX[i]))
        parent = name
    w(f'  <link name="{p}link8"/>')
    joint(p + "joint8", "fixed", parent, p + "link8", xyz=(0, 0, PANDA_FLANGE_D))
    # Franka Hand: rotated -45 deg about the flange z; fingers 0.0584 m, TCP 0.1034 m out.
    link(p + "hand", collisions=[(("box", (0.06, 0.21, 0.06)), (0, 0, 0.03), (0, 0, 0))],
         visuals=[(("box", (0.05, 0.2, 0.055)), (0, 0, 0.03), (0, 0, 0))], mass=0.73, material="white")
    joint(p + "hand_joint", "fixed", p + "link8", p + "hand", rpy=(0, 0, -PI/4))
    w(f'  <link name="{p}hand_tcp"/>')
    joint(p + "hand_tcp_joint", "fixed", p + "hand", p + "hand_tcp", xyz=(0, 0, 0.1034))
    for k, sgn in [(1, 1), (2, -1)]:
        fname = f"{p}finger{k}"
        link(fname, collisions=[(("box", (0.02, 0.015, 0.05)), (0, sgn * 0.0075, 0.025), (0, 0, 0))],
             mass=0.015, material="dark")
        joint(f"{p}finger_joint{k}", "prismatic", p + "hand", fname, xyz=(0, 0, 0.0584),
              axis=(0, sgn, 0), limit=(0.0, 0.04, 70.0, 0.2))

arm("left", ARM_Y)
arm("right", -ARM_Y)
w("</robot>")

import sys
# Optional argument: write there instead (the crate test compares it with the checked-in file).
path = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(os.path.abspath(__file__)), "agrisim_robot.urdf")
with open(path, "w") as fh:
    fh.write("\n".join(out) + "\n")
