"""ROS in a mission: which modules a mission imports are ROS's, what of them aeroexec stands in for, and the
stand-ins that let a mission import a ROS module it never uses.

A mission written for Aerostack (ROS 1) or Aerostack2 (ROS 2) imports ROS modules. aeroexec provides the parts
that are the drone interface (:func:`provided`: ``rclpy.init``/``ok``/``shutdown``, a script's own node and its
spinning, Aerostack2's ``as2_python_api`` and the constants of ``as2_msgs.msg``); any other ROS module imports as
a stand-in whose every use raises :class:`RosFeatureError`, naming what was used and that the mission uses ROS
beyond the drone interface. The static check (:mod:`aeroexec.engine.missions.check`) says the same before flight: a
use is an error at its line, an import never used a warning. Registered with the core through entry points
(:data:`IMPORTS`: the finder and the imports judged by use; :data:`CHECKS`: the check of a program's ROS uses).
"""

from __future__ import annotations

import functools
import importlib.machinery
import importlib.util
import sys
import threading
import types
from pathlib import Path

from aeroexec.engine import api
from aeroexec.engine.missions import standins
from aeroexec.engine.missions.dialect_checks import DialectChecks
from aeroexec.engine.missions.standins import StandIns

TYPE_CHECKING = False  # typing is not imported at run time (type checkers read the block below)
if TYPE_CHECKING:
    from typing import Any

#: Packages of both ROS 1 and ROS 2 (the image stack): their use is refused in the words of the mission's ROS.
BOTH_ROS_PACKAGES = frozenset({"message_filters", "cv_bridge", "image_transport"})
#: ROS 1 packages (Aerostack's missions): their use is refused in ROS 1's words.
ROS1_PACKAGES = frozenset({"rospy", "roslib", "rosbag", "rosgraph", "rosnode", "rosservice", "rostopic",
                           "actionlib", "tf", "dynamic_reconfigure", "mavros", "aerostack_msgs", "droneMsgsROS"})
#: ROS 2 packages that are no message packages.
ROS2_PACKAGES = frozenset({"rclpy", "rclpy_message_converter", "rosbag2_py", "rosidl_runtime_py", "launch",
                           "launch_ros", "ament_index_python", "tf2_ros", "tf2_py", "tf2_geometry_msgs",
                           "tf_transformations", "python_interface", "as2_core", "as2_motion_reference_handlers"})
#: What aeroexec provides of ROS modules as the drone interface, by module: the names a mission may use (``*``: the
#: whole module). :func:`provided` adds the messages used as data.
_INTERFACE: dict[str, frozenset[str]] = {
    "rclpy": frozenset({"init", "shutdown", "try_shutdown", "ok", "logging", "node", "executors", "parameter", "time",
                        "duration", "clock", "timer", "task", "exceptions", "publisher", "utilities", "spin",
                        "spin_once", "spin_until_future_complete", "create_node", "get_global_executor", "qos",
                        "callback_groups"}),
    # a script's own node, as far as it needs no ROS 2 graph (aerostack2/rclpy/node.py; its graph's methods are
    # refused by the check of nodes, aerostack2/ros_nodes.py)
    "rclpy.node": frozenset({"Node"}),
    "rclpy.executors": frozenset({"Executor", "SingleThreadedExecutor", "MultiThreadedExecutor",
                                  "ExternalShutdownException", "ShutdownException"}),
    "rclpy.parameter": frozenset({"Parameter"}),
    "rclpy.time": frozenset({"Time"}),
    "rclpy.duration": frozenset({"Duration"}),
    "rclpy.clock": frozenset({"Clock", "ClockType", "ROSClock"}),
    "rclpy.timer": frozenset({"Timer"}),
    "rclpy.task": frozenset({"Future"}),
    "rclpy.publisher": frozenset({"Publisher"}),
    "rclpy.callback_groups": frozenset({"CallbackGroup", "MutuallyExclusiveCallbackGroup", "ReentrantCallbackGroup"}),
    # QoS profiles as data, for the publishers served (aerostack2/rclpy/qos.py: its __all__)
    "rclpy.qos": frozenset({
        "DurabilityPolicy", "HistoryPolicy", "InvalidQoSProfileException", "LivelinessPolicy", "QoSDurabilityPolicy",
        "QoSHistoryPolicy", "QoSLivelinessPolicy", "QoSPresetProfiles", "QoSProfile", "QoSReliabilityPolicy",
        "ReliabilityPolicy", "qos_profile_action_status_default", "qos_profile_parameter_events",
        "qos_profile_parameters", "qos_profile_sensor_data", "qos_profile_services_default",
        "qos_profile_system_default"}),
    "rclpy.utilities": frozenset({"remove_ros_args", "ok", "get_default_context"}),
    "rclpy.exceptions": frozenset({"ParameterNotDeclaredException", "ParameterAlreadyDeclaredException",
                                   "ParameterUninitializedException", "InvalidParameterTypeException",
                                   "ParameterException", "NotInitializedException"}),
    "as2_msgs": frozenset({"msg"}),
    "as2_msgs.msg": frozenset({"YawMode", "BehaviorStatus", "PlatformStatus", "AlertEvent", "PoseWithID",
                               "PoseWithIDArray", "TrajectoryWaypoints"}),
    "as2_python_api": frozenset({"drone_interface", "drone_interface_base", "drone_interface_gps",
                                 "drone_interface_teleop", "modules", "behavior_actions", "mission_interpreter"}),
    "as2_python_api.modules": frozenset({
        "module_base", "takeoff_module", "land_module", "go_to_module", "follow_path_module", "rtl_module",
        "navigate_to_module", "go_to_gps_module", "follow_path_gps_module", "point_gimbal_module",
        "follow_reference_module", "gps_module", "motion_reference_handler_module"}),
    "as2_python_api.behavior_actions": frozenset({"behavior_handler"}),
    "as2_python_api.mission_interpreter": frozenset({"mission", "mission_interpreter"}),
    # as2_python_api's name in Aerostack2 before 1.0 (the package was renamed as2_python_api in December 2022),
    # with that version's module names
    "python_interface": frozenset({"drone_interface", "drone_interface_base", "drone_interface_gps",
                                   "drone_interface_teleop", "modules", "behaviour_actions"}),
    "python_interface.modules": frozenset({
        "module_base", "takeoff_module", "land_module", "goto_module", "follow_path_module", "goto_gps_module",
        "follow_path_gps_module", "gps_module", "motion_reference_handler_module"}),
    "python_interface.behaviour_actions": frozenset({"behavior_handler"}),
    "rclpy.logging": frozenset({"get_logger"}),
}


def _messages() -> dict[str, dict[str, type]]:
    """The messages used as data (dialects/ros_messages.py), by module: imported on the first ROS name a check or a
    stand-in meets, not by every program's check (~0.5 ms of every start)."""
    from aeroexec.dialects.ros_messages import MESSAGES

    return MESSAGES


@functools.cache
def _provided() -> dict[str, frozenset[str]]:
    """What aeroexec provides of ROS modules, by module: the drone interface and the messages used as data (built,
    filled and read, never published)."""
    messages = _messages()
    return {**_INTERFACE, **{module.partition(".")[0]: frozenset({"msg"}) for module in messages},
            **{module: frozenset(types) for module, types in messages.items()}}


#: The words of every refusal.
ROS2_BEYOND = "this mission uses ROS 2 beyond the drone interface"
ROS1_BEYOND = "this mission uses ROS beyond Aerostack's mission API"


class RosFeatureError(RuntimeError):
    """A mission used a part of ROS that aeroexec does not provide."""


def is_ros(module: str) -> bool:
    """True for a module of a ROS package (ROS 1 or 2; message, service and action packages included)."""
    top = module.split(".")[0]
    return (top in ROS1_PACKAGES or top in ROS2_PACKAGES or top in BOTH_ROS_PACKAGES
            or top.endswith(("_msgs", "_srvs", "_interfaces")) or top.startswith("as2_")
            or top in IMAGE_LIBRARIES and not installed(top))


#: What ROS's image stack gives a mission its images as (cv_bridge's OpenCV arrays): where it is not installed, an
#: import of it is judged by its use as ROS's modules are (a mission written for ROS 2 has it from ROS 2).
IMAGE_LIBRARIES = {"cv2": "OpenCV"}
#: The words of a refused use of a missing image library.
NO_IMAGES = "is not installed here, and aeroexec's drone interface gives no camera images to process"


@functools.cache
def installed(module: str) -> bool:
    """True when the top-level ``module`` can be imported from the environment's own paths."""
    return importlib.machinery.PathFinder.find_spec(module) is not None


#: The modules of Aerostack's (ROS 1) mission APIs: a mission importing them uses ROS 1's message packages.
AEROSTACK_APIS = ("executive_engine_api", "mission_execution_control")


def beyond(module: str, ros1: bool = False) -> str:
    """The refusal's words for a use of ``module`` (a message package's in ROS 1's words when ``ros1``)."""
    top = module.split(".")[0]
    if top in IMAGE_LIBRARIES:
        return f"{IMAGE_LIBRARIES[top]} ({top}) {NO_IMAGES}"
    if top in ROS1_PACKAGES or (ros1 and top not in ROS2_PACKAGES and not top.startswith("as2_")):
        return ROS1_BEYOND
    return ROS2_BEYOND


def provided(path: str, ros1: bool = False) -> bool:
    """True when ``path`` (``module`` or ``module.name``) is something aeroexec provides (ROS 2's messages as data
    only to a ROS 2 mission: ``ros1`` False)."""
    provided_names = _provided()
    if ros1 and f"{path.partition('.')[0]}.msg" in _messages():
        return False
    if path in provided_names:
        return True
    module, _, name = path.rpartition(".")
    while module:
        names = provided_names.get(module)
        if names is not None:
            return "*" in names or name in names
        module, _, name = module.rpartition(".")
    return False


class Refused:
    """What a mission gets for a ROS name aeroexec does not provide: any use of it raises RosFeatureError."""

    def __init__(self, name: str) -> None:
        object.__setattr__(self, "_name", name)

    def _refuse(self, *args: Any, **kwargs: Any) -> Any:
        name = object.__getattribute__(self, "_name")
        raise RosFeatureError(f"{name}: {beyond(name)}")

    def __getattr__(self, attribute: str) -> Any:
        if attribute.startswith("__") and attribute.endswith("__"):
            raise AttributeError(attribute)
        return Refused(f"{object.__getattribute__(self, '_name')}.{attribute}")

    __call__ = __setattr__ = __iter__ = __getitem__ = __bool__ = __len__ = __eq__ = __hash__ = _refuse
    # a topic name built of it ('/' + ns + '/' + as2.topics...), a number read from it: the use is the refusal
    __add__ = __radd__ = __sub__ = __mul__ = __truediv__ = __lt__ = __le__ = __gt__ = __ge__ = _refuse
    __contains__ = __int__ = __float__ = __index__ = __format__ = __fspath__ = _refuse

    def __mro_entries__(self, bases: tuple) -> tuple:  # class Mine(Node): ... uses ROS
        self._refuse()
        return ()

    def __repr__(self) -> str:
        return f"<{object.__getattribute__(self, '_name')}: not available without ROS>"


def refusing_module(name: str) -> types.ModuleType:
    """A module every attribute of which is :class:`Refused` (a submodule is a module like it)."""
    module = types.ModuleType(name, f"aeroexec's stand-in for {name}: {beyond(name)}")
    module.__path__ = []  # a package: its submodules are stand-ins too
    for type_name, message_type in _messages().get(name, {}).items():  # messages used as data are served
        setattr(module, type_name, message_type)
    module.__getattr__ = lambda attribute: (Refused(f"{name}.{attribute}") if not attribute.startswith("__")
                                            else _no_attribute(attribute))
    return module


def _no_attribute(attribute: str) -> Any:
    raise AttributeError(attribute)


class _StandInLoader:  # importlib.abc.Loader's protocol, without importing importlib.abc (see RosStandIns)
    def __init__(self, name: str) -> None:
        self.name = name  # the module as the mission named it

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> types.ModuleType:
        return refusing_module(self.name)

    def exec_module(self, module: types.ModuleType) -> None:
        return None


class RosStandIns:
    """Found last on ``sys.meta_path``: a ROS module nothing else provides imports as a refusing stand-in (a
    module of ROS's that aeroexec's own stand-ins lack too: ``rclpy.action``, ...aerostack2.rclpy.action).
    A finder of ``importlib.abc.MetaPathFinder``'s protocol (``find_spec``), not its subclass: importing
    :mod:`importlib.abc` imports importlib.resources, tempfile, shutil and random (~5 ms of every run's start)."""

    def find_spec(self, fullname: str, path: Any = None, target: Any = None) -> importlib.machinery.ModuleSpec | None:
        name = _as_imported(fullname)
        if not is_ros(name) or name == fullname and standins.stands_in(name):
            return None  # rclpy, as2_msgs...: a mission's are aeroexec's (standins), nobody else's are stand-ins
        return importlib.machinery.ModuleSpec(fullname, _StandInLoader(name), is_package=True)


def _as_imported(fullname: str) -> str:
    """A module of a package serving a mission's import, under the name the mission imports it by."""
    for top, package in standins.served().items():
        if fullname == package or fullname.startswith(package + "."):
            return top + fullname[len(package):]
    return fullname


FINDER = RosStandIns()
# The stand-ins here (and the dialects' APIs beside them) are aeroexec's code: a place in a message is the mission's.
api.add_library_folder(Path(__file__).resolve().parent)
_lock = threading.Lock()


def install() -> None:
    """Let missions import ROS modules they never use (idempotent; the finder comes after every other one)."""
    with _lock:
        if FINDER not in sys.meta_path:
            sys.meta_path.append(FINDER)




def ros_problems(nodes: list[Any], dotted: Any) -> list[tuple[Any, str, str]]:
    """``(node, severity, message)`` for the ROS a program uses beyond what aeroexec provides: an error at each
    line that uses it, a warning at an import nothing uses. ``nodes`` are the program's AST nodes,
    ``dotted(node)`` the checker's dotted path of an expression (``rospy.init_node``) through its imports."""
    import ast

    imports: list[tuple[ast.stmt, str]] = []  # (statement, imported path)
    modules: set[str] = set()
    for node in nodes:
        if isinstance(node, ast.Import):
            imports += [(node, a.name) for a in node.names if is_ros(a.name)]
            modules |= {a.name.split(".")[0] for a in node.names}
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            modules.add(node.module.split(".")[0])
            if is_ros(node.module):
                imports += [(node, f"{node.module}.{a.name}") for a in node.names if a.name != "*"]
    if not imports:
        return []
    ros1 = bool(modules & ROS1_PACKAGES) or bool(modules & set(AEROSTACK_APIS))
    problems: list[tuple[Any, str, str]] = []
    used: set[str] = set()  # imported paths something uses
    seen: set[tuple[int, str]] = set()
    outermost = {id(n.value) for n in nodes if isinstance(n, ast.Attribute)}
    for node in nodes:
        if not isinstance(node, ast.Name | ast.Attribute) or id(node) in outermost:
            continue
        if isinstance(node, ast.Name) and not isinstance(node.ctx, ast.Load):
            continue
        path = dotted(node)
        if not path or not is_ros(path):
            continue
        for _, imported in imports:
            if path == imported or path.startswith(imported + ".") or imported.startswith(path + "."):
                used.add(imported)
        if not provided(path, ros1) and (node.lineno, path) not in seen:
            seen.add((node.lineno, path))
            problems.append((node, "error", f"{path}: {beyond(path, ros1)}"))
    for statement, imported in imports:
        if imported not in used and not provided(imported, ros1):
            problems.append((statement, "warning", f"{imported} is imported but never used: the mission runs "
                                                   f"without it (a use would be refused: {beyond(imported, ros1)})"))
    return problems


IMPORTS = StandIns(finders=("aeroexec.dialects.ros:FINDER",), judged_by_use="aeroexec.dialects.ros:is_ros")
CHECKS = DialectChecks(problems="aeroexec.dialects.ros:ros_problems")

__all__ = ["BOTH_ROS_PACKAGES", "CHECKS", "FINDER", "IMAGE_LIBRARIES", "IMPORTS", "ROS1_BEYOND",
           "ROS2_BEYOND", "Refused", "RosFeatureError",
           "beyond", "install", "installed", "is_ros", "provided", "refusing_module", "ros_problems"]
