"""The simulated multicopter's parameters (:class:`SimConfig`), with PX4-like defaults.

The PX4 parameter each default follows is named in its comment; times in seconds, speeds in m/s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class SimConfig:
    """Limits, rates, battery and failsafe settings of the simulated drone."""

    # Motion
    max_speed: float = 12.0  # horizontal, MPC_XY_VEL_MAX
    cruise_speed: float = 5.0  # default go-to speed, MPC_XY_CRUISE
    max_acceleration: float = 3.0  # horizontal, MPC_ACC_HOR
    vertical_acceleration: float = 3.0  # MPC_ACC_DOWN_MAX (MPC_ACC_UP_MAX is 4)
    climb_rate: float = 1.5  # take-off climb, MPC_TKO_SPEED
    max_climb_rate: float = 3.0  # other climbs, MPC_Z_VEL_MAX_UP
    descent_rate: float = 1.5  # descents and landing above land_slow_altitude, MPC_Z_VEL_MAX_DN
    land_speed: float = 0.7  # final landing descent, MPC_LAND_SPEED
    land_slow_altitude: float = 5.0  # below it landing descends at land_speed, MPC_LAND_ALT2
    land_fast_altitude: float = 10.0  # above it landing descends at descent_rate, MPC_LAND_ALT1
    yaw_rate: float = 45.0  # deg/s, MPC_YAWRAUTO_MAX
    position_gain: float = 3.0  # 1/s: how briskly the last meters to a target close (MPC_XY_P is 0.95)
    default_takeoff_altitude: float = 2.5  # m, MIS_TAKEOFF_ALT
    acceptance_radius: float = 0.5  # m: a go-to has arrived within it (NAV_ACC_RAD is 2)
    return_altitude: float = 10.0  # m: return-to-launch climbs to it first (RTL_RETURN_ALT is 60)
    ceiling: float | None = None  # m above home the vehicle may climb to (a --vehicle profile's); None: no ceiling
    camera: bool = True  # the vehicle has a camera (a --vehicle profile's camera: false: its photos are skipped)

    # Battery
    battery_hover_minutes: float = 20.0  # 100 % to 0 % hovering
    battery_speed_drain: float = 0.5  # extra drain at max_speed, as a fraction of hover drain
    battery_climb_drain: float = 0.5  # extra drain climbing at max_climb_rate, as a fraction of hover drain
    battery_idle_drain: float = 0.1  # armed on the ground, as a fraction of hover drain
    battery_cells: int = 4  # LiPo cells in series (4S: 16.8 V full)
    initial_battery_percent: float = 100.0
    failsafe_battery_percent: float = 7.0  # at or below it: no arming, and a flying drone lands (BAT_CRIT_THR)

    # Landing and safety
    disarm_delay: float = 2.0  # s on the ground after landing before auto-disarm, COM_DISARM_LAND
    preflight_disarm_delay: float = 10.0  # s armed on the ground without taking off, COM_DISARM_PRFLT
    drone_radius: float = 0.3  # m: a collision is the obstacle closer than this to the drone's center
    crash_speed: float = 3.0  # m/s: touching the ground faster than this is a crash
    touch_distance: float = 0.5  # m: the drone touches an object whose position is this close to its center
    gravity: float = 9.81  # m/s^2: how a crashed drone falls (and a dropped item)
    payload: tuple[str, ...] | None = None  # names of the items carried (None: the world's ``payload``)

    # Simulation
    start: tuple[float, float] = (0.0, 0.0)  # m east, north: where the drone stands at first and returns to
    substep: float = 0.02  # s: fixed integration step
    position_noise_std: float = 0.0  # m: reported position noise (0 = exact), seeded
    detection_probability: float = 1.0  # chance that a camera reports an object in view, each update, seeded

    # Weather and link
    wind: tuple[float, float] = (0.0, 0.0)  # m/s east, north: the mean wind (blows the drone; airspeed drains)
    wind_gust: float = 0.0  # m/s: standard deviation of the gusts about the mean (a 5 s correlation), seeded
    link_loss: tuple[float, float] | None = None  # (at, for) s of simulated time: the ground station's link drops

    def __post_init__(self) -> None:
        for name in ("max_speed", "cruise_speed", "max_acceleration", "vertical_acceleration", "climb_rate",
                     "max_climb_rate", "descent_rate", "land_speed", "yaw_rate", "position_gain",
                     "default_takeoff_altitude", "acceptance_radius", "battery_hover_minutes", "substep"):
            if not getattr(self, name) > 0.0:
                raise ValueError(f"SimConfig.{name} must be positive, not {getattr(self, name)}")
        if self.position_gain * self.substep >= 1.0:
            raise ValueError("SimConfig.position_gain * substep must stay below 1 for a stable approach")
        if not 0.0 <= self.initial_battery_percent <= 100.0:
            raise ValueError(f"SimConfig.initial_battery_percent must be in 0..100, not {self.initial_battery_percent}")
        if not 0.0 <= self.detection_probability <= 1.0:
            raise ValueError(f"SimConfig.detection_probability must be in 0..1, not {self.detection_probability}")
        if self.wind_gust < 0.0 or not all(math.isfinite(w) for w in self.wind):
            raise ValueError("SimConfig.wind must be finite and wind_gust not negative")
        if self.link_loss is not None and not (self.link_loss[0] >= 0.0 and self.link_loss[1] > 0.0):
            raise ValueError(f"SimConfig.link_loss must be (at >= 0, for > 0) seconds, not {self.link_loss}")
        if self.ceiling is not None and not self.ceiling > 0.0:
            raise ValueError(f"SimConfig.ceiling must be positive, not {self.ceiling}")
        if self.position_noise_std < 0.0:
            raise ValueError("SimConfig.position_noise_std cannot be negative")
