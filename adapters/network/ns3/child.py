"""The radio's process: ``python -m adapters.network.ns3.child`` serves one run's radio.

It reads requests from its standard input and answers on its standard output (frames of
:mod:`adapters.network.ns3.wire`); whatever C++ prints goes to its standard error, which
the run keeps the tail of. Requests:

- ``("setup", kwargs)``: build the radio (:class:`~adapters.network.ns3.radio.Radio`);
  answers the seconds it took;
- ``("step", {"positions": (n, 2) or None, "sends": (t_ns, src, ids, nbytes) or None,
  "until": t_ns, "stop_on_rx": bool})``: move the nodes, schedule the sends, run to
  ``until`` (or to the first reception); answers ``(rx bytes, drop bytes, seconds, the
  radio's time in ns)``;
- ``("abort", None)``: make ns-3 abort this process (to test that a run contains it);
- ``("exit", None)``: answer and exit.

A request the radio refuses is answered ``("err", kind, text)`` and the process serves on.
"""

from __future__ import annotations

import os
import signal
import sys
import time
from typing import Any

from adapters.network.ns3.wire import read_frame, write_frame


def serve() -> None:
    """Answer requests until ``exit`` or until the run closes the pipe."""
    answers = os.fdopen(os.dup(1), "wb", buffering=0)  # the protocol's own channel
    os.dup2(2, 1)  # anything else printed goes to standard error
    sys.stdout = sys.stderr
    requests = os.fdopen(os.dup(0), "rb", buffering=0)
    started = time.perf_counter()
    from adapters.network.ns3 import radio  # ns-3: seconds

    imported_s = time.perf_counter() - started
    # cppyy's handler runs a debugger on SIGABRT for seconds: die at once, ns-3 has
    # already printed why
    signal.signal(signal.SIGABRT, signal.SIG_DFL)
    current: Any = None
    while True:
        try:
            command, argument = read_frame(requests)
        except EOFError:
            break
        try:
            if command == "setup":
                if current is not None:
                    current.close()
                t = time.perf_counter()
                current = radio.Radio(**argument)
                result: Any = {"import_s": imported_s, "setup_s": time.perf_counter() - t}
            elif command == "step":
                t = time.perf_counter()
                if argument["positions"] is not None:
                    current.set_positions(argument["positions"])
                if argument["sends"] is not None:
                    current.send_many(*argument["sends"])
                rx, drops = current.run_until(
                    argument["until"], stop_on_rx=argument.get("stop_on_rx", False)
                )
                result = (rx.tobytes(), drops.tobytes(), time.perf_counter() - t, current.now_ns)
            elif command == "reasons":
                result = radio.REASONS
            elif command == "abort":
                current.abort_for_test()
                result = None
            elif command == "exit":
                write_frame(answers, ("ok", None))
                break
            else:
                raise ValueError(f"unknown request {command!r}")
            write_frame(answers, ("ok", result))
        except Exception as e:  # told to the run; the radio serves on
            write_frame(answers, ("err", type(e).__name__, str(e)))
    if current is not None:
        current.close()


if __name__ == "__main__":
    serve()
