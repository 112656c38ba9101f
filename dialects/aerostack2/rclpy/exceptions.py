"""``rclpy.exceptions`` as a mission sees it: the exceptions of parameters and of a context, with rclpy's names."""

from __future__ import annotations

from typing import Any


class NotInitializedException(Exception):
    """rclpy was used before ``rclpy.init()``."""


class ParameterException(Exception):
    """A parameter could not be declared, read or set."""

    def __init__(self, message: str, parameters: Any = ()) -> None:
        super().__init__(message, list(parameters) if not isinstance(parameters, str) else [parameters])


class ParameterNotDeclaredException(ParameterException):
    """A parameter the node never declared (and the node does not allow undeclared ones)."""

    def __init__(self, parameters: Any) -> None:
        super().__init__("Invalid access to undeclared parameter(s)", parameters)


class ParameterAlreadyDeclaredException(ParameterException):
    def __init__(self, parameters: Any) -> None:
        super().__init__("Parameter(s) already declared", parameters)


class ParameterUninitializedException(ParameterException):
    """A parameter declared with a type and no value, read before it was given one."""

    def __init__(self, parameter: str) -> None:
        super().__init__(f"The parameter '{parameter}' is not initialized", parameter)


class InvalidParameterTypeException(ParameterException):
    """A parameter given a value of another type than its declared one (ROS 2 parameters are statically typed)."""

    def __init__(self, parameter: Any, expected: Any) -> None:
        Exception.__init__(self, f"Trying to set parameter '{parameter.name}' to '{parameter.value}' of type "
                                 f"'{parameter.type_.name}', expecting type '{expected.name}'")


__all__ = ["InvalidParameterTypeException", "NotInitializedException", "ParameterAlreadyDeclaredException",
           "ParameterException", "ParameterNotDeclaredException", "ParameterUninitializedException"]
