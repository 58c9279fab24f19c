"""The packed FMUs simulated by FMPy (`simulate_fmu`, FMI 3 and FMI 2 builds) against analytic
answers. FMPy takes the co-simulation step from `output_interval`, so every call passes 0.02."""

from __future__ import annotations

import math

import numpy as np
import pytest
from fmpy import simulate_fmu

from agrisim_fmpy import fmu_path

H = 0.02
VERSIONS = [3, 2]
# Ideal actuators: every limit at its declared maximum (the FMU refuses values above the
# modelDescription's max, e.g. steer_rate_max <= 1e9), watchdog off.
IDEAL = {"steer_rate_max": 1e9, "wheel_speed_max": 1e9, "wheel_accel_max": 1e12, "cmd_timeout": 0.0}


def simulate(name: str, version: int, stop: float, start_values: dict, outputs: list[str]):
    r = simulate_fmu(str(fmu_path(name, version)), stop_time=stop, output_interval=H,
                     start_values=start_values, output=outputs)
    n = round(stop / H)
    assert len(r["time"]) == n + 1, f"{len(r['time'])} output points, expected {n + 1}"
    assert np.allclose(r["time"], np.arange(n + 1) * H, rtol=0, atol=1e-12)
    return r


def wrap(a):
    return (np.asarray(a) + math.pi) % (2 * math.pi) - math.pi


# ------------------------------------------------------------------------------ chassis


@pytest.mark.parametrize("version", VERSIONS)
def test_kinematic_straight_line_with_acceleration_limit(version):
    # wheel accel 10 rad/s^2 x r 0.1 m = 1 m/s^2: ramp 1 s to 1 m/s, then constant speed.
    r = simulate("ChassisKinematic", version, 3.0, {"cmd_vx": 1.0, "cmd_timeout": 0.0}, ["x", "y", "yaw", "vx"])
    t = r["time"]
    x_exact = np.where(t <= 1.0, t * t / 2, t - 0.5)
    err = np.max(np.abs(r["x"] - x_exact))
    assert err < 1e-6, f"max |x - x(t)| = {err:.3e}"
    assert np.max(np.abs(r["y"])) == 0.0 and np.max(np.abs(r["yaw"])) == 0.0
    assert np.max(np.abs(r["vx"] - np.minimum(t, 1.0))) < 1e-9


@pytest.mark.parametrize("version", VERSIONS)
def test_kinematic_circle_matches_se2_arc(version):
    v, vy, w = 0.6, 0.2, 0.3
    x0, y0, yaw0 = 1.0, -0.5, 0.5
    start = dict(IDEAL, cmd_vx=v, cmd_vy=vy, cmd_wz=w, x0=x0, y0=y0, yaw0=yaw0)
    r = simulate("ChassisKinematic", version, 30.0, start, ["x", "y", "yaw", "odom_x", "odom_y", "odom_yaw"])
    t = r["time"]
    # Body twist (v, vy, w) held constant: p(t) = p0 + R(yaw0) [ (sin wt v - (1 - cos wt) vy) / w,
    #                                                        ((1 - cos wt) v + sin wt vy) / w ]
    s, c = np.sin(w * t), np.cos(w * t)
    bx, by = (s * v - (1 - c) * vy) / w, ((1 - c) * v + s * vy) / w
    xa = x0 + math.cos(yaw0) * bx - math.sin(yaw0) * by
    ya = y0 + math.sin(yaw0) * bx + math.cos(yaw0) * by
    ex, ey = np.max(np.abs(r["x"] - xa)), np.max(np.abs(r["y"] - ya))
    eyaw = np.max(np.abs(wrap(r["yaw"] - (yaw0 + w * t))))
    assert ex < 1e-6 and ey < 1e-6 and eyaw < 1e-6, f"errors x {ex:.2e}, y {ey:.2e}, yaw {eyaw:.2e}"
    assert np.max(np.abs(r["x"] - x0)) > 1.0, "the base must actually move around the circle"
    # Noise-free odometry equals ground truth.
    assert np.max(np.abs(r["odom_x"] - r["x"])) < 1e-9 and np.max(np.abs(r["odom_y"] - r["y"])) < 1e-9


NOISE = {"cmd_vx": 0.8, "cmd_wz": 0.1, "cmd_timeout": 0.0,
         "enc_noise": 0.2, "steer_noise": 0.01, "slip_mean": 0.02, "slip_std": 0.05}
ODOM = ["x", "y", "yaw", "odom_x", "odom_y", "odom_yaw", "odom_vx"]


@pytest.mark.parametrize("version", VERSIONS)
def test_odometry_drifts_and_is_seeded(version):
    run = lambda seed: simulate("ChassisKinematic", version, 20.0, dict(NOISE, seed=seed), ODOM)
    a, a2, b = run(1), run(1), run(2)
    drift = math.hypot(a["odom_x"][-1] - a["x"][-1], a["odom_y"][-1] - a["y"][-1])
    assert drift > 0.05, f"odometry drift {drift} m after 20 s should be visible"
    for name in ODOM:
        assert np.array_equal(a[name], a2[name]), f"same seed, {name} differs"
    assert not np.array_equal(a["odom_x"], b["odom_x"]), "other seed, same odometry"
    # Ground truth does not depend on the encoders' noise, but slip (also seeded) moves it.
    assert not np.array_equal(a["x"], b["x"])


@pytest.mark.parametrize("version", VERSIONS)
def test_dynamic_chassis_settles_near_command_and_differs_from_kinematic(version):
    start = {"cmd_vx": 1.0, "cmd_timeout": 0.0}
    d = simulate("ChassisDynamic", version, 5.0, start, ["x", "y", "vx"])
    k = simulate("ChassisKinematic", version, 5.0, start, ["x", "y", "vx"])
    assert abs(d["vx"][-1] - 1.0) < 0.05, f"dynamic vx {d['vx'][-1]}"
    assert np.all(np.isfinite(d["x"])) and abs(d["y"][-1]) < 1e-6
    assert d["x"][-1] != k["x"][-1] and abs(d["x"][-1] - k["x"][-1]) < 0.5
    assert np.max(np.abs(d["vx"] - k["vx"])) > 1e-3, "same physics as the kinematic model?"


# ------------------------------------------------------------------------------ lift


def trapezoid(t, p0, p1, vmax, amax):
    """Rest-to-rest time-optimal profile from p0 to p1 starting at t = 0 (closed form)."""
    d, s = abs(p1 - p0), math.copysign(1.0, p1 - p0)
    vp = min(vmax, math.sqrt(amax * d))
    ta = vp / amax
    tc = max(d - vp * vp / amax, 0.0) / vp
    T = 2 * ta + tc
    t = np.asarray(t)
    pos = np.where(t < ta, 0.5 * amax * t * t,
                   np.where(t < ta + tc, 0.5 * amax * ta * ta + vp * (t - ta),
                            np.where(t < T, d - 0.5 * amax * (T - t) ** 2, d)))
    vel = np.where(t < ta, amax * t, np.where(t < ta + tc, vp, np.where(t < T, amax * (T - t), 0.0)))
    return p0 + s * pos, s * vel, T


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("setpoint", [0.6, 0.0, 0.25], ids=["up-trapezoid", "down-trapezoid", "triangle"])
def test_lift_follows_exact_trapezoid(version, setpoint):
    r = simulate("Lift", version, 4.0, {"setpoint": setpoint}, ["position", "velocity", "status", "target", "payload_height"])
    p, v, T = trapezoid(r["time"], 0.2, setpoint, 0.2, 0.5)
    ep, ev = np.max(np.abs(r["position"] - p)), np.max(np.abs(r["velocity"] - v))
    assert ep < 1e-9 and ev < 1e-9, f"position error {ep:.2e}, velocity error {ev:.2e}"
    assert r["position"][-1] == pytest.approx(setpoint, abs=1e-12) and T < 4.0
    assert np.all(r["target"] == setpoint)
    moving = r["time"] < T - 1e-9
    assert np.all(r["status"][moving] == 1) and np.all(r["status"][~moving] == 0)
    assert np.max(np.abs(r["payload_height"] - (0.45 + r["position"]))) < 1e-12


@pytest.mark.parametrize("version", VERSIONS)
@pytest.mark.parametrize("setpoint", [1.0, -0.1])
def test_lift_refuses_out_of_range_setpoint(version, setpoint):
    r = simulate("Lift", version, 1.0, {"setpoint": setpoint}, ["position", "velocity", "status", "target"])
    assert np.all(r["status"] == 2)
    assert np.all(r["position"] == 0.2) and np.all(r["velocity"] == 0.0) and np.all(r["target"] == 0.2)
