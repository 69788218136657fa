"""An ``auvtrack`` command in a child process for the signal tests: its stderr lines as they come, its children."""
from __future__ import annotations

import os
import queue
import subprocess
import sys
import threading
import time
from pathlib import Path
from typing import Callable

ROOT = Path(__file__).resolve().parents[1]
HANG_S = 60.0
"""Generous bound on every wait (a hang fails the test instead of blocking it)."""


class CliProcess:
    """``python -m auvtrack.cli ARGS`` with this checkout first on the path; stderr read line by line."""

    def __init__(self, args: list[str], env: dict | None = None, cwd: str | Path | None = None) -> None:
        full_env = {**os.environ, "PYTHONPATH": str(ROOT), **(env or {})}
        self.proc = subprocess.Popen([sys.executable, "-m", "auvtrack.cli", *args], stdout=subprocess.PIPE,
                                     stderr=subprocess.PIPE, text=True, env=full_env, cwd=cwd)
        self.lines: list[str] = []
        self._queue: queue.Queue = queue.Queue()
        self._out: list[str] = []
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()
        self._out_reader = threading.Thread(target=lambda: self._out.append(self.proc.stdout.read()), daemon=True)
        self._out_reader.start()

    def __enter__(self) -> "CliProcess":
        return self

    def __exit__(self, *exc) -> None:
        if self.proc.poll() is None:  # a failed test: do not leave the command running
            self.proc.kill()
            self.proc.wait()
        self._reader.join(HANG_S)
        self._out_reader.join(HANG_S)
        self.proc.stdout.close()
        self.proc.stderr.close()

    def _read(self) -> None:
        for line in self.proc.stderr:
            for part in line.replace("\r", "\n").splitlines():
                self._queue.put(part)
        self._queue.put(None)

    def wait_for(self, predicate: Callable[[str], bool], bound: float = HANG_S) -> str:
        """The first stderr line meeting ``predicate``; AssertionError if the process ends or ``bound`` s pass first."""
        deadline = time.monotonic() + bound
        while True:
            try:
                line = self._queue.get(timeout=max(deadline - time.monotonic(), 0.01))
            except queue.Empty:
                raise AssertionError(f"no such line within {bound} s; stderr so far:\n" + "\n".join(self.lines))
            if line is None:
                raise AssertionError("the process ended first; stderr:\n" + "\n".join(self.lines))
            self.lines.append(line)
            if predicate(line):
                return line

    def finish(self, bound: float = HANG_S) -> tuple[int, str, str]:
        """Wait for the exit (at most ``bound`` s): exit status, stdout, the whole stderr."""
        try:
            self.proc.wait(timeout=bound)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            raise AssertionError(f"still running {bound} s later; stderr:\n" + "\n".join(self.lines)) from None
        self._reader.join(bound)
        self._out_reader.join(bound)
        while not self._queue.empty() and (line := self._queue.get()) is not None:
            self.lines.append(line)
        return self.proc.returncode, "".join(self._out), "\n".join(self.lines)

    def children(self) -> list[int]:
        """Process ids whose parent is this process (Linux: read from /proc)."""
        kids = []
        for entry in Path("/proc").iterdir():
            if entry.name.isdigit():
                try:
                    stat = (entry / "stat").read_text()
                except OSError:
                    continue
                if int(stat.rsplit(")", 1)[1].split()[1]) == self.proc.pid:
                    kids.append(int(entry.name))
        return kids


def alive(pid: int) -> bool:
    """Whether ``pid`` runs (a zombie does not)."""
    try:
        stat = Path(f"/proc/{pid}/stat").read_text()
    except OSError:
        return False
    return stat.rsplit(")", 1)[1].split()[0] != "Z"


def wait_gone(pids: list[int], bound: float = HANG_S) -> list[int]:
    """The processes of ``pids`` still running after at most ``bound`` s (empty when all ended)."""
    deadline = time.monotonic() + bound
    while (left := [p for p in pids if alive(p)]) and time.monotonic() < deadline:
        time.sleep(0.2)
    return left
