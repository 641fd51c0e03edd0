"""Python LeafSystems that Python's collector can free once their diagram has flown.

In pydrake 1.51.1 a Diagram holding a LeafSystem written in Python is never freed, with
everything its systems hold (plans, NLPs, verification diagrams: about 0.2 GB per re-planning
sample; RobotLocomotion/drake issues 22515 and 23161). Two kinds of reference cycle pass
through C++, where the collector cannot see them:

- a callback given to Drake (output-port calc, event handler, witness function) that is a
  bound method or a closure over the system: the system's C++ part holds the callback and
  the callback holds the system. ``weak_method`` gives Drake a callback that reaches its
  system through a weak reference instead;
- the links pydrake adds between a system and its builder and port objects
  (``_pydrake_internal_ref_cycle_peers``, a set on each of them, so that a port or a system
  keeps its diagram alive). ``release_system`` removes them once a diagram has flown; the
  links to the event callbacks (tuples) are kept, Drake calls them.

With both, every system of a flown diagram is freed when its last Python reference goes
(tests/test_lifetime.py holds the closed loop and the plan-verification flights to that).
"""
from __future__ import annotations

import weakref

from pydrake.systems.framework import Diagram

__all__ = ["weak_method", "weak_element", "release_system", "REF_CYCLE_PEERS"]

#: the attribute in which pydrake keeps an object's reference-cycle links (pydrake's
#: ref_cycle_pybind.cc); absent in a pydrake without them, where release_system does nothing
REF_CYCLE_PEERS = "_pydrake_internal_ref_cycle_peers"


def weak_method(method, *args):
    """A callback for Drake that calls the bound ``method`` with its call's arguments followed by
    ``args``, holding the method's system only weakly (a bound method or a lambda over ``self``
    given to a Declare... call keeps the system alive for ever: module docstring)."""
    system, function = weakref.ref(method.__self__), method.__func__

    def callback(*call_args):
        owner = system()
        if owner is None:  # Drake never calls a callback of a freed system; say so if it does
            raise RuntimeError(f"{function.__qualname__} called after its system was freed")
        return function(owner, *call_args, *args)

    callback.__qualname__ = f"weak {function.__qualname__}"
    return callback


def weak_element(method, index: int):
    """An output-port calc for a 1-vector port: element ``index`` of ``method(context)`` (a bound
    method of the port's system, held as ``weak_method`` holds it)."""
    value = weak_method(method)

    def calc(context, output):
        output.SetAtIndex(0, value(context)[index])

    return calc


def _python_implemented(system) -> bool:
    return not type(system).__module__.startswith("pydrake.")


def _unlink(system) -> int:
    """Removes the builder and port links of one Python system, both ways: the number removed."""
    peers = getattr(system, "__dict__", {}).get(REF_CYCLE_PEERS)
    if peers is None:
        return 0
    linked = [peer for peer in peers if not isinstance(peer, tuple)]  # tuples: event callbacks
    for peer in linked:
        peers.discard(peer)
        back = getattr(peer, "__dict__", {}).get(REF_CYCLE_PEERS)
        if back is not None:
            back.discard(system)
    return len(linked)


def release_system(system) -> int:
    """Lets ``system`` be freed when its last Python reference goes (module docstring): removes
    pydrake's builder and port links of every Python-implemented system in it (a Diagram: each
    of its systems, nested diagrams included, and itself when it is a Diagram subclass written in
    Python, as systems.native_plant's are; a LeafSystem never added to a diagram holds such
    links to its ports too). Call it once the system has flown and everything wanted from it
    has been read: a port object taken from one of its systems afterwards makes a new link.
    Returns the number of links removed."""
    removed = _unlink(system) if _python_implemented(system) else 0
    if isinstance(system, Diagram):
        for child in system.GetSystems():
            removed += release_system(child)
    return removed
