"""What a sweep prints at the end, gathered as results arrive: memory flat in the number of sets.

``SweepSummary.add(result)`` counts the set, keeps for each battery item the worst
error/tolerance ratio and the set it came from (ties go to the set earlier in the
sweep, whatever order the results arrive in), and keeps the ``FAILURES_SHOWN``
failures earliest in the sweep; the result itself is then dropped.  ``table()`` is the
summary: pass and fail counts, the worst ratio per item, those failures.
"""

from __future__ import annotations

import heapq
import re
from dataclasses import dataclass, field

from pendverify.certify.sweep_task import SetResult

FAILURES_SHOWN = 20
_INDEX = re.compile(r"-(\d+)$")  # a set's name ends with its index in the sweep


def _index(name: str) -> int:
    match = _INDEX.search(name)
    return int(match[1]) if match else 0


@dataclass
class SweepSummary:
    sets: int = 0
    passed: int = 0
    worst: dict = field(default_factory=dict)  # item name → (ratio, −index, set name)
    _failures: list = field(default_factory=list)  # heap of (−index, name, reason), the earliest kept

    @property
    def failed(self) -> int:
        return self.sets - self.passed

    def add(self, result: SetResult) -> None:
        self.sets += 1
        self.passed += result.passed
        index = _index(result.name)
        for item in result.items:
            entry = (item.ratio, -index, result.name)
            if item.name not in self.worst or entry > self.worst[item.name]:
                self.worst[item.name] = entry
        if not result.passed:
            reason = result.error or ", ".join(i.name for i in result.items if not i.passed)
            heapq.heappush(self._failures, (-index, result.name, reason))
            if len(self._failures) > FAILURES_SHOWN:
                heapq.heappop(self._failures)  # the latest in the sweep

    def table(self) -> str:
        lines = [f"{self.passed} passed, {self.failed} failed, {self.sets} sets"]
        width = max((len(k) for k in self.worst), default=5)
        lines.append(f"{'check'.ljust(width)}  worst error/tolerance  set")
        lines += [
            f"{name.ljust(width)}  {m:21.3g}  {who}" for name, (m, _, who) in sorted(self.worst.items())
        ]
        lines += [f"FAIL {name}: {reason}" for _, name, reason in sorted(self._failures, reverse=True)]
        if self.failed > len(self._failures):
            lines.append(f"... and {self.failed - len(self._failures)} more failed")
        return "\n".join(lines)
