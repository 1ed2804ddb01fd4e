"""The errors the ``tactex`` package raises: one base, :class:`TactexError`, and a subclass
per kind of mistake that is also the built-in exception a caller would catch for it. Their
messages name the keyword (``depth_mm``) where the native library names the CLI's flag
(``--depth-mm``): one typed error, said in the caller's words."""

from __future__ import annotations

import re
from typing import Any, Callable, TypeVar

__all__ = ["TactexError", "InvalidArgument", "MissingFile", "Failure"]


class TactexError(Exception):
    """Base of every error the package raises."""


class InvalidArgument(TactexError, ValueError):
    """What was given is wrong: an argument's value, a file's contents, a prompt."""


class MissingFile(TactexError, FileNotFoundError):
    """A file or directory that was named is not there."""


class Failure(TactexError, RuntimeError):
    """The machinery failed on good input (a device, a solver, the disk)."""


# Flags whose keyword is not the flag's own name.
_KEYWORD = {"at_mm": "pose", "yaw_deg": "pose"}


def python_words(message: str) -> str:
    """A native message with each CLI flag (``'--depth-mm <DEPTH_MM>'``, ``--depth-mm``) said
    as the keyword that stands for it (``'depth_mm'``, ``depth_mm``)."""

    def keyword(match: "re.Match[str]") -> str:
        name = match.group(1).replace("-", "_")
        return _KEYWORD.get(name, name)

    message = re.sub(r"--([a-z][a-z0-9-]*) <[A-Z0-9_]+>", keyword, message)
    return re.sub(r"--([a-z][a-z0-9-]*)", keyword, message)


F = TypeVar("F", bound=Callable[..., Any])


def translated(fn: F) -> F:
    """``fn`` raising this package's errors, in the caller's words, for the built-in ones the
    native library raises."""

    def call(*args: Any, **kwargs: Any) -> Any:
        try:
            return fn(*args, **kwargs)
        except TactexError:
            raise
        except FileNotFoundError as e:
            raise MissingFile(python_words(str(e))) from None
        except ValueError as e:
            raise InvalidArgument(python_words(str(e))) from None
        except RuntimeError as e:
            raise Failure(python_words(str(e))) from None

    call.__name__ = getattr(fn, "__name__", "call")
    call.__doc__ = getattr(fn, "__doc__", None)
    return call  # type: ignore[return-value]
