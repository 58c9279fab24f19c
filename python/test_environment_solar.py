"""The camera's sun position (NREL SPA in fmus/lib/sky/src/solar.rs, read from the Camera
FMU's solar_zenith / solar_azimuth outputs) against pvlib's independent SPA implementation,
over random dates, times, time zones and places; and the FMU's refusal of bad [environment]
keys. pvlib gets the same instant in UTC, the same pressure, temperature and elevation, and
computes Delta T itself (delta_t=None), so Delta T is checked too."""

from __future__ import annotations

import math
import random

import fmpy
import numpy as np
import pandas as pd
import pvlib
import pytest
from fmpy import read_model_description
from fmpy.fmi3 import FMU3Slave

from agrisim_fmpy import fmu_path

CASES = 150
# SPA's own uncertainty is 0.0003 deg; two implementations of it agree far better than that
# except for rounding in Delta T and float order, so 0.001 deg is a strict bound.
TOLERANCE_DEG = 1e-3


@pytest.fixture(scope="module")
def camera(tmp_path_factory):
    """A factory of initialized Camera instances sharing one unpacked library."""
    fmu = fmu_path("Camera")
    md = read_model_description(str(fmu))
    unzip = fmpy.extract(str(fmu), str(tmp_path_factory.mktemp("camera")))
    refs = {v.name: v.valueReference for v in md.modelVariables}
    count = [0]

    def solar(environment: str) -> tuple[float, float] | str:
        count[0] += 1
        s = FMU3Slave(guid=md.guid, unzipDirectory=unzip, modelIdentifier=md.coSimulation.modelIdentifier,
                      instanceName=f"camera{count[0]}")
        s.instantiate()
        try:
            s.setInt32([refs["width"], refs["height"]], [2, 2])
            s.setString([refs["environment"]], [environment])
            try:
                s.enterInitializationMode(startTime=0.0)
                s.exitInitializationMode()
            except Exception as e:  # noqa: BLE001 - the FMU's error status is the answer
                return f"refused: {e}"
            zen, az = s.getFloat64([refs["solar_zenith"], refs["solar_azimuth"]])
            s.terminate()
            return zen, az
        finally:
            s.freeInstance()

    return solar


def direction(zenith: float, azimuth: float) -> np.ndarray:
    z, a = math.radians(zenith), math.radians(azimuth)
    return np.array([math.sin(z) * math.sin(a), math.sin(z) * math.cos(a), math.cos(z)])


def test_sun_position_matches_pvlib(camera):
    rng = random.Random(20251122)
    worst_angle = worst_zenith = worst_azimuth = 0.0
    for _ in range(CASES):
        year = rng.randint(1990, 2060)
        month, day = rng.randint(1, 12), rng.randint(1, 28)
        hour, minute, second = rng.randint(0, 23), rng.randint(0, 59), rng.randint(0, 59)
        offset = rng.randint(-12, 14)
        lat, lon = rng.uniform(-66.0, 66.0), rng.uniform(-180.0, 180.0)
        elev = rng.uniform(0.0, 3000.0)
        pressure, temp = rng.uniform(700.0, 1040.0), rng.uniform(-20.0, 40.0)
        env = (f'date = "{year:04d}-{month:02d}-{day:02d}"\ntime = "{hour:02d}:{minute:02d}:{second:02d}"\n'
               f"utc_offset = {float(offset)}\nlatitude = {lat!r}\nlongitude = {lon!r}\nelevation = {elev!r}\n"
               f"pressure = {pressure!r}\ntemperature = {temp!r}\n")
        got = camera(env)
        assert not isinstance(got, str), f"{env}: {got}"
        local = pd.Timestamp(year=year, month=month, day=day, hour=hour, minute=minute, second=second)
        utc = (local - pd.Timedelta(hours=offset)).tz_localize("UTC")
        ref = pvlib.solarposition.spa_python(pd.DatetimeIndex([utc]), lat, lon, altitude=elev,
                                             pressure=pressure * 100.0, temperature=temp, delta_t=None)
        zen_ref, az_ref = float(ref["apparent_zenith"].iloc[0]), float(ref["azimuth"].iloc[0])
        angle = math.degrees(math.acos(min(1.0, float(direction(*got) @ direction(zen_ref, az_ref)))))
        worst_angle = max(worst_angle, angle)
        worst_zenith = max(worst_zenith, abs(got[0] - zen_ref))
        if zen_ref < 89.0:  # azimuth is ill-conditioned near the zenith only through sin(z)
            worst_azimuth = max(worst_azimuth, abs((got[1] - az_ref + 180.0) % 360.0 - 180.0) * math.sin(math.radians(zen_ref)))
        assert angle < TOLERANCE_DEG, f"{env}: agrisim {got} pvlib ({zen_ref}, {az_ref})"
    print(f"\n{CASES} cases: max angle {worst_angle:.2e} deg, max |zenith error| {worst_zenith:.2e} deg, "
          f"max azimuth error x sin(zenith) {worst_azimuth:.2e} deg")


@pytest.mark.parametrize("text,key", [
    ("latitude = 91.0", "latitude"),
    ('weather = "snow"', "weather"),
    ('date = "2025-13-01"', "date"),
    ("humidity = 101.0", "humidity"),
    ('render_quality = "ultra"', "render_quality"),
])
def test_bad_environment_is_refused(camera, text, key):
    got = camera(text)
    assert isinstance(got, str), f"{text}: accepted"
