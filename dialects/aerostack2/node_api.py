"""The methods of a ROS 2 node, by name: which a script's own node is served (``rclpy.node.Node``'s stand-in,
:mod:`aeroexec.dialects.aerostack2.rclpy.node`) and which need a ROS 2 graph (refused by name, and by the check
before flight: :mod:`aeroexec.dialects.aerostack2.ros_nodes`). A table only: the check reads it without importing
the stand-in."""

#: The beginnings of the names of a ROS 2 node's own methods: one not served is refused by name.
NODE_API = ("create_", "destroy_", "declare_", "get_", "set_", "has_", "add_", "remove_", "undeclare_",
            "describe_", "list_", "count_", "wait_for_")
#: The node's methods and members served (the rest of NODE_API's needs a ROS 2 graph: subscriptions, services...).
SERVED = frozenset({
    "get_logger", "get_name", "get_namespace", "get_fully_qualified_name", "get_clock", "declare_parameter",
    "declare_parameters", "get_parameter", "get_parameters", "get_parameter_or", "has_parameter", "set_parameters",
    "undeclare_parameter", "add_on_set_parameters_callback", "remove_on_set_parameters_callback", "create_timer",
    "destroy_timer", "create_publisher", "destroy_publisher", "destroy_node", "timers", "publishers", "executor",
    "context", "default_callback_group"})


def needs_graph(method: str) -> bool:
    """True for a node's method that needs a ROS 2 graph (``create_subscription``, ``create_client``...)."""
    return method.startswith(NODE_API) and method not in SERVED


__all__ = ["NODE_API", "SERVED", "needs_graph"]
