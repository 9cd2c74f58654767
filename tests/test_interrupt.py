"""numerics.interrupt: a signal whose KeyboardInterrupt lands where Python cannot raise it (a weakref callback)
prints no traceback and still stops the work (the flag); other unraisable errors are still reported."""
import signal
import sys
import weakref

import pytest

from balloon_cg.numerics import interrupt


class Thing:
    pass


def _collected_with(callback):
    """Create and drop an object whose weakref callback is ``callback`` (run at once, by reference counting)."""
    thing = Thing()
    ref = weakref.ref(thing, lambda _: callback())
    del thing
    return ref


@pytest.mark.parametrize("handlers", [interrupt.sigterm_raises, interrupt.stop_on_signals])
def test_an_interrupt_inside_a_callback_is_not_printed_and_sets_the_flag(monkeypatch, handlers):
    reported = []
    monkeypatch.setattr(sys, "unraisablehook", reported.append)
    with handlers():
        if handlers is interrupt.stop_on_signals:
            interrupt.request()  # the first signal is pending: the second raises
        _collected_with(lambda: signal.raise_signal(signal.SIGTERM))  # the handler runs inside the callback
        assert interrupt.requested()
        assert reported == []  # without the hook: "Exception ignored in ..." and a KeyboardInterrupt traceback
        _collected_with(lambda: 1 / 0)
        assert [type(r.exc_value) for r in reported] == [ZeroDivisionError]  # a bug is still shown
    assert sys.unraisablehook == reported.append and not interrupt.requested()
