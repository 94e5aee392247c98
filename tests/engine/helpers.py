"""Shared helpers of the engine tests."""

from engine.events import drain


def events_and_result(gen):
    """Every event (left) in an engine event generator, and its return value."""
    events = []
    result = drain(gen, events.append)
    return events, result
