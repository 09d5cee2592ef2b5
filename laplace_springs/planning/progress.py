"""A one-line progress bar on stderr, for long evaluations and the benchmark harness."""

from __future__ import annotations

import sys
import time
from typing import TextIO

__all__ = ["Progress"]


class Progress:
    """A one-line progress bar on a stream (a line per label when it is not a terminal).

    >>> import io
    >>> out = io.StringIO()
    >>> bar = Progress(2, stream=out)
    >>> bar.update("chain-200", "refined"); bar.advance(); bar.close()
    >>> out.getvalue().splitlines()[0]
    '[0/2] chain-200'
    """

    WIDTH = 28

    def __init__(self, total: int, stream: TextIO | None = None, enabled: bool = True,
                 unit: str = "runs") -> None:
        self.total, self.done, self.enabled, self.unit = max(total, 1), 0, enabled, unit
        if not enabled:  # nothing is shown: no clock, no look at the stream
            return
        self.stream = stream if stream is not None else sys.stderr
        self.start = time.perf_counter()
        self.terminal = bool(getattr(self.stream, "isatty", lambda: False)())
        self._last_label: str | None = None

    def update(self, label: str, detail: str = "") -> None:
        """Show the bar at its current count, with what is being done."""
        if not self.enabled:
            return
        if not self.terminal:
            if label != self._last_label:
                self._last_label = label
                self._write(f"[{self.done}/{self.total}] {label}\n")
            return
        filled = self.WIDTH * self.done // self.total
        bar = "#" * filled + "-" * (self.WIDTH - filled)
        elapsed = time.perf_counter() - self.start
        self._write(f"\r[{bar}] {self.done}/{self.total} {elapsed:5.0f}s "
                    f"{label[:24]}: {detail[:18]}".ljust(100))

    def advance(self, count: int = 1) -> None:
        self.done += count

    def close(self) -> None:
        if self.enabled:
            elapsed = time.perf_counter() - self.start
            self._write(("\r" if self.terminal else "")
                        + f"done: {self.done} {self.unit} in {elapsed:.0f} s".ljust(100) + "\n")

    def _write(self, text: str) -> None:
        self.stream.write(text)
        self.stream.flush()
