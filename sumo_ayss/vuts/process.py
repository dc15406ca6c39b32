"""An external process as a VUT controller: the line protocol (version 1) over its pipes.

For driving stacks that are neither Python nor an FMU: the testbed starts the program named
by ``process.command`` and talks to it over its standard input and output, one UTF-8 line
per message, ``\\n``-terminated, fields separated by single spaces. Standard error is the
program's own (kept in a file; its last lines appear in errors).

==========================================  ===========================  =================
testbed writes                              the process answers          when
==========================================  ===========================  =================
``sumo_ayss-vut 1 <signal> <signal> ...``   ``ok 1``                     once, at start
``reset <k>``                               ``ok``                       every episode
``step <k> <value> <value> ...``            ``accel <m/s²>``             every SUMO step
``quit``                                    (nothing; it exits)          at the end
==========================================  ===========================  =================

* The hello line names the protocol, its version and the signals
  (:data:`~sumo_ayss.vuts.signals.SIGNALS`) whose values every ``step`` line carries, in that
  order. A process that does not speak version 1 answers ``error <why>``.
* ``k`` (0, 1, ...) is the VUT instance. One process serves every instance of the same VUT
  configuration in one testbed process (the pairs of a vectorised env: 8 in training, up
  to 256 when responses are measured), each with its own episodes: a controller with state
  keeps one state per ``k`` and resets only ``k``'s on ``reset <k>``. Requests are
  strictly one at a time (an answer before the next request).
* Values: reals in Python's ``repr`` (``20.5``, ``inf`` for no leader), integers in
  decimal, truth values as ``1``/``0``. The answer's number is parsed by ``float``.
* Any answer may instead be ``error <message>``: the run stops with that message.
* Timing: ``step`` is sent after SUMO step ``t``; the answer acts during step ``t + 1``
  (exactly a Python controller's timing, :mod:`sumo_ayss.vuts.controllers`). No answer within
  ``call_deadline_s`` (``start_timeout_s`` for the hello) stops the run.

Errors (:class:`~sumo_ayss.util.errors.ControllerError`, one line, naming the process): it
exited (with its exit code and last stderr lines), answered late, or answered something
else than the protocol allows. The process is killed; whatever the run had written stays
(the job fails like one whose controller raised, and is not retried).

A reference client in Python is ``examples/process_vut.py``.
"""

from __future__ import annotations

import contextlib
import json
import os
import select
import subprocess
import tempfile
import time
import weakref
from typing import IO, Any, NoReturn

from sumo_ayss.util.errors import ConfigError, ControllerError
from sumo_ayss.vuts.process_spec import ProcessSpec
from sumo_ayss.vuts.signals import SIGNALS

__all__ = ["PROTOCOL", "PROTOCOL_VERSION", "ProcessController", "format_value"]

#: The protocol's name and version, as the hello line writes them.
PROTOCOL = "sumo_ayss-vut"
PROTOCOL_VERSION = 1


def format_value(value: float | int | bool) -> str:
    """A signal value as the protocol writes it (``repr`` reals, ``1``/``0`` truth values)."""
    if isinstance(value, bool):
        return "1" if value else "0"
    if isinstance(value, int):
        return str(value)
    return repr(float(value))


class _Connection:
    """One running process and its pipe, shared by the controllers of one configuration."""

    def __init__(self, spec: ProcessSpec, where: str, error: type[Exception]) -> None:
        self.spec = spec
        self.label = spec.label
        self.users: set[int] = set()
        self._next_id = 0
        # Closed by the finalizer (_stop), with the process: it outlives this call.
        self._stderr: IO[bytes] = tempfile.TemporaryFile(prefix="sumo_ayss_vut_")  # noqa: SIM115
        try:
            self.proc: subprocess.Popen[bytes] | None = subprocess.Popen(
                list(spec.command),
                cwd=spec.cwd or None,
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=self._stderr,
                bufsize=0,
            )
        except OSError as e:
            self._stderr.close()
            raise error(
                f"{where}.command: cannot start {self.label} ({type(e).__name__}: {e})"
            ) from e
        self._buffer = b""
        self._finalizer = weakref.finalize(self, _stop, self.proc, self._stderr)
        hello = " ".join([PROTOCOL, str(PROTOCOL_VERSION), *spec.signals])
        try:
            answer = self.ask(hello, spec.start_timeout_s, "the hello")
            if answer != f"ok {PROTOCOL_VERSION}":
                self.garbage(answer, f"'ok {PROTOCOL_VERSION}'", "the hello")
        except ControllerError as e:
            raise error(f"{where}: {e}") from None

    def new_id(self) -> int:
        """A fresh instance number ``k`` for one more controller."""
        k = self._next_id
        self._next_id += 1
        self.users.add(k)
        return k

    def release(self, k: int) -> None:
        """Instance ``k`` is done; the last one stops the process."""
        self.users.discard(k)
        if not self.users:
            self.close()

    def close(self) -> None:
        """Stop the process (``quit``, then kill if it lingers); safe to call twice."""
        if self.proc is not None:
            self.proc = None
            self._finalizer()
            if _CONNECTIONS.get(_key(self.spec)) is self:
                del _CONNECTIONS[_key(self.spec)]

    def ask(self, line: str, timeout_s: float, what: str) -> str:
        """Write ``line``, return the answer line (an ``error`` answer raises)."""
        proc = self.proc
        if proc is None or proc.stdin is None or proc.stdout is None:
            raise ControllerError(f"{self.label} is stopped (asked for {what})")
        try:
            proc.stdin.write(line.encode() + b"\n")
            proc.stdin.flush()
        except OSError:
            self._died(what)
        deadline = time.monotonic() + timeout_s
        fd = proc.stdout.fileno()
        while b"\n" not in self._buffer:
            remaining = deadline - time.monotonic()
            ready = select.select([fd], [], [], remaining)[0] if remaining > 0 else []
            if not ready:
                proc.kill()  # it is not answering: do not wait for it to quit
                self.close()
                raise ControllerError(
                    f"{self.label}: no answer to {what} within {timeout_s:g} s "
                    f"({'start_timeout_s' if what == 'the hello' else 'call_deadline_s'}); "
                    "the process was stopped"
                )
            chunk = os.read(fd, 65536)
            if not chunk:
                self._died(what)
            self._buffer += chunk
        raw, _, self._buffer = self._buffer.partition(b"\n")
        answer = raw.decode("utf-8", errors="replace").strip()
        if answer.startswith("error"):
            self.close()
            raise ControllerError(f"{self.label} reported an error at {what}: {answer[5:].strip()}")
        return answer

    def garbage(self, answer: str, expected: str, what: str) -> NoReturn:
        """Stop the process: it answered outside the protocol."""
        self.close()
        raise ControllerError(
            f"{self.label} answered {answer[:200]!r} to {what}; protocol "
            f"{PROTOCOL} {PROTOCOL_VERSION} expects {expected}"
        )

    def _died(self, what: str) -> NoReturn:
        code = None
        if self.proc is not None:
            with contextlib.suppress(subprocess.TimeoutExpired):
                code = self.proc.wait(timeout=1.0)
        tail = self._stderr_tail()
        self.close()
        raise ControllerError(
            f"{self.label} exited (code {code}) before answering {what}"
            + (f"; its last stderr: {tail}" if tail else "")
        )

    def _stderr_tail(self) -> str:
        try:
            self._stderr.seek(0)
            lines = self._stderr.read().decode("utf-8", errors="replace").strip().splitlines()
        except (OSError, ValueError):
            return ""
        return " | ".join(lines[-3:])[:400]


#: The running process of each configuration in this Python process, by :func:`_key`.
_CONNECTIONS: dict[str, _Connection] = {}


def _key(spec: ProcessSpec) -> str:
    return json.dumps(spec.to_dict(), sort_keys=True)


def _connection(spec: ProcessSpec, where: str, error: type[Exception]) -> _Connection:
    conn = _CONNECTIONS.get(_key(spec))
    if conn is None or conn.proc is None:
        conn = _CONNECTIONS[_key(spec)] = _Connection(spec, where, error)
    return conn


class ProcessController:
    """One VUT instance ``k`` served by the configuration's process (``reset``,
    ``acceleration``), see the module docstring.

    Args:
        spec: The process's configuration.
        where: The config field, for errors (``env.vuts.<name>.process``).

    Raises:
        ConfigError: The program cannot be started or does not answer the hello in time.
    """

    def __init__(self, spec: ProcessSpec, where: str = "process") -> None:
        self.spec = spec
        self.where = where
        self.label = spec.label
        self._reads = [SIGNALS[name].read for name in spec.signals]
        self._conn: _Connection | None = _connection(spec, where, ConfigError)
        self._k = self._conn.new_id()
        self._fresh = True  # the first episode needs no reset

    def reset(self) -> None:
        """Start an episode (``reset <k>`` -> ``ok``); a stopped process is started again."""
        conn = self._live()
        if conn is None:
            conn = self._conn = _connection(self.spec, self.where, ControllerError)
            self._k = conn.new_id()
        elif self._fresh:
            self._fresh = False
            return
        self._fresh = False
        answer = conn.ask(f"reset {self._k}", self.spec.call_deadline_s, "reset")
        if answer != "ok":
            conn.garbage(answer, "'ok'", "reset")

    def acceleration(self, state: Any) -> float:
        """The process's command for the coming step [m/s²]."""
        conn = self._live()
        if conn is None:
            raise ControllerError(f"{self.label}: asked for a command after close()")
        self._fresh = False
        values = " ".join(format_value(read(state)) for read in self._reads)
        answer = conn.ask(f"step {self._k} {values}", self.spec.call_deadline_s, "step")
        word, _, number = answer.partition(" ")
        if word == "accel":
            try:
                return float(number)
            except ValueError:
                pass
        conn.garbage(answer, "'accel <number>'", "step")

    def close(self) -> None:
        """Release this instance; the last instance of a configuration stops its process
        (safe to call twice; the next :meth:`reset` starts it again if needed)."""
        if self._conn is not None:
            self._conn.release(self._k)
            self._conn = None

    def _live(self) -> _Connection | None:
        conn = self._conn
        if conn is not None and conn.proc is None:  # stopped by an error or another close
            self._conn = None
            return None
        return conn


def _stop(proc: subprocess.Popen[bytes], stderr: IO[bytes]) -> None:
    """Ask a process to quit, then kill it if it lingers (also at garbage collection)."""
    try:
        if proc.poll() is None and proc.stdin is not None:
            with contextlib.suppress(OSError):
                proc.stdin.write(b"quit\n")
                proc.stdin.close()
            try:
                proc.wait(timeout=2.0)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        if proc.stdout is not None:
            proc.stdout.close()
    finally:
        stderr.close()
