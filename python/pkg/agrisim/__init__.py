"""agrisim from Python: the greenhouse co-simulation, its messages, benchmarks and
gymnasium environments.

    import agrisim
    with agrisim.Simulation("default", seed=1) as sim:
        sim.publish("/cmd_vel", {"linear": {"x": 0.3}})
        sim.step(50)                       # 1 s at 0.02 s
        odom = sim.latest("/odom")         # a dict of the nav_msgs/Odometry fields

Importing the package registers the environments ``agrisim/Navigate-v0`` and
``agrisim/Reach-v0`` with gymnasium (when gymnasium is installed).
"""

from . import _agrisim
from ._agrisim import *  # noqa: F401,F403  (Simulation, Snapshot, Node, NavTask, ArmModel, ...)
from ._agrisim import __version__  # noqa: F401  (the crates' version)
from . import bench, msg  # noqa: F401
from .msg import image_to_array, pointcloud_to_array  # noqa: F401

__all__ = [*_agrisim.__all__, "bench", "image_to_array", "msg", "pointcloud_to_array"]

try:
    import gymnasium  # noqa: F401
except ImportError:  # the environments need gymnasium; the rest does not
    pass
else:
    from . import envs  # noqa: F401

    envs.register_all()
