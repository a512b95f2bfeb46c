"""Registries that map a kind (a joint class, a node class, a feature class) to a handler.

Each consumer that must do something per kind (rebuild it in pymunk, draw it,
cut it, compose it into a toy) keeps one :class:`Registry`, filled by a
decorator next to the code that handles the kind (ezdxf's ``register_entity``
pattern)::

    REBUILDERS = Registry("simulate", "joint kind")

    @REBUILDERS.register(Pivot)
    def _pivot(joint, rebuild): ...

Look-ups are by exact type: a subclass or a look-alike copy of a kind is a
kind of its own and must be registered, so nothing is handled by a guess.
A kind with no entry raises :class:`UnsupportedError` naming the consumer and
the kind; registering a kind twice raises :class:`TypeError`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from typing import Generic, TypeVar

from planar.errors import PlanarError

__all__ = ["Registry", "UnsupportedError", "kind_name"]

H = TypeVar("H")


class UnsupportedError(PlanarError):
    """A consumer met a kind it has no handler for (the message names both)."""


def kind_name(kind: type | object) -> str:
    """The name a kind goes by: its ``kind`` class attribute, else its class name."""
    cls = kind if isinstance(kind, type) else type(kind)
    name = cls.__dict__.get("kind")
    return name if isinstance(name, str) else cls.__name__


class Registry(Generic[H]):
    """Handlers of one consumer, keyed by kind (a class), looked up by exact type."""

    def __init__(self, consumer: str, noun: str = "joint kind") -> None:
        self.consumer = consumer
        self.noun = noun
        self._handlers: dict[type, H] = {}

    def register(self, *kinds: type) -> Callable[[H], H]:
        """Decorator: ``handler`` handles every class in ``kinds``."""

        def deco(handler: H) -> H:
            for k in kinds:
                if k in self._handlers:
                    raise TypeError(f"{self.consumer}: double registration for {self.noun} {kind_name(k)!r}")
                self._handlers[k] = handler
            return handler

        return deco

    def get(self, obj: object, what: str = "") -> H:
        """The handler for ``obj``'s exact type; :class:`UnsupportedError` if there is none.

        ``what`` names the object in the message (e.g. ``"joint 'B'"``).
        """
        handler = self._handlers.get(type(obj))
        if handler is None:
            where = f" ({what})" if what else ""
            known = ", ".join(sorted(kind_name(k) for k in self._handlers))
            raise UnsupportedError(
                f"{self.consumer} has no handler for {self.noun} {kind_name(obj)!r}{where}; it handles: {known}"
            )
        return handler

    def __contains__(self, kind: object) -> bool:
        cls = kind if isinstance(kind, type) else type(kind)
        return cls in self._handlers

    def kinds(self) -> Iterator[type]:
        """The registered kinds, in registration order."""
        return iter(self._handlers)
