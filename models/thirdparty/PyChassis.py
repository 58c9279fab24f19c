"""A mobile-base model written in plain Python and exported with pythonfmu (FMI 2.0
co-simulation): the kind of third-party component agrisim lets users swap in.

It knows nothing of ROS: Real velocity commands in (base frame, REP 103: x forward, y left,
yaw counter-clockwise), Real pose and velocities out. agrisim's adapter FMUs turn
/cmd_vel (geometry_msgs/Twist) into its inputs and its outputs into nav_msgs/Odometry
(models/systems/thirdparty/swap_chassis.ssd; docs/guides/swap-component.md).

The model: an omnidirectional base whose body velocities follow the command with
acceleration and speed limits (the built-in chassis's wheel limits, 10 rad/s^2 and 15 rad/s
on 0.1 m wheels, give 1.0 m/s^2 and 1.5 m/s), its pose integrated exactly along the arc
travelled in one step at constant body velocity.

Build:  pythonfmu build -f models/thirdparty/PyChassis.py -d target/fmu/thirdparty
"""

import math

from pythonfmu import Fmi2Causality, Fmi2Slave, Fmi2Variability, Real


def _toward(v, target, dv):
    """v moved toward target by at most dv."""
    return v + max(-dv, min(dv, target - v))


def _clamp(v, limit):
    return max(-limit, min(limit, v))


class PyChassis(Fmi2Slave):
    author = "agrisim"
    description = "Omnidirectional base: velocity commands in, pose and velocities out (Python, pythonfmu)"

    def __init__(self, **kwargs):
        super().__init__(**kwargs)
        self.x0 = 0.0
        self.y0 = 0.0
        self.yaw0 = 0.0
        self.accel_max = 1.0
        self.yaw_accel_max = 2.5
        self.speed_max = 1.5
        self.yaw_rate_max = 2.0
        self.cmd_vx = 0.0
        self.cmd_vy = 0.0
        self.cmd_wz = 0.0
        self.x = 0.0
        self.y = 0.0
        self.yaw = 0.0
        self.vx = 0.0
        self.vy = 0.0
        self.wz = 0.0
        param = dict(causality=Fmi2Causality.parameter, variability=Fmi2Variability.fixed)
        # Setting the start pose also places the base there, so outputs read during
        # initialization are already right.
        self.register_variable(Real("x0", **param, setter=lambda v: self._start(x=v)))
        self.register_variable(Real("y0", **param, setter=lambda v: self._start(y=v)))
        self.register_variable(Real("yaw0", **param, setter=lambda v: self._start(yaw=v)))
        for name in ("accel_max", "yaw_accel_max", "speed_max", "yaw_rate_max"):
            self.register_variable(Real(name, **param))
        for name in ("cmd_vx", "cmd_vy", "cmd_wz"):
            self.register_variable(Real(name, causality=Fmi2Causality.input))
        for name in ("x", "y", "yaw", "vx", "vy", "wz"):
            self.register_variable(Real(name, causality=Fmi2Causality.output))

    def _start(self, **pose):
        for k, v in pose.items():
            setattr(self, k + "0", v)
            setattr(self, k, v)

    def do_step(self, current_time, step_size):
        h = step_size
        self.vx = _toward(self.vx, _clamp(self.cmd_vx, self.speed_max), self.accel_max * h)
        self.vy = _toward(self.vy, _clamp(self.cmd_vy, self.speed_max), self.accel_max * h)
        self.wz = _toward(self.wz, _clamp(self.cmd_wz, self.yaw_rate_max), self.yaw_accel_max * h)
        # Exact SE(2) motion at constant body velocity over h.
        dth = self.wz * h
        if abs(dth) < 1e-9:
            a, b = 1.0 - dth * dth / 6.0, dth / 2.0
        else:
            a, b = math.sin(dth) / dth, (1.0 - math.cos(dth)) / dth
        dx = (a * self.vx - b * self.vy) * h
        dy = (b * self.vx + a * self.vy) * h
        c, s = math.cos(self.yaw), math.sin(self.yaw)
        self.x += c * dx - s * dy
        self.y += s * dx + c * dy
        self.yaw = math.atan2(math.sin(self.yaw + dth), math.cos(self.yaw + dth))
        return True
