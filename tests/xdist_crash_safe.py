"""pytest-xdist's file-grouped scheduling (``--dist loadfile``, this suite's default), made safe against a worker
that dies in a test (a native crash, or pytest-timeout ending a hung test).

xdist puts the dead worker's unfinished file back in the queue *including the test it died in*: the replacement
worker runs that test again and dies again, until ``--max-worker-restart`` is spent, and then the controller waits
forever for work no worker will take (reproduced with xdist 3.8.0: a file holding one segfaulting test hangs
``pytest -n 2 --dist loadfile``). Here the test a worker died in is reported failed once (xdist's "worker 'gw0'
crashed while running ...") and never re-run; the rest of its file runs on the replacement worker, which is
given enough work to start (see ``_reschedule``).

Loaded by ``tests/conftest.py``; usable on its own with ``-p xdist_crash_safe`` (this directory on ``sys.path``).
"""

from __future__ import annotations

from typing import Any

import pytest


def _crash_safe_loadfile(config: pytest.Config, log: Any) -> Any:
    from xdist.scheduler import LoadFileScheduling

    class CrashSafeLoadFileScheduling(LoadFileScheduling):
        def remove_node(self, node: Any) -> str | None:
            """As xdist's, except that the test the node died in is marked done before its file is re-queued."""
            workload = self.assigned_work.pop(node)
            pending = [(scope, nodeid) for scope, unit in workload.items()
                       for nodeid, done in unit.items() if not done]
            if not pending:  # a clean shutdown
                return None
            scope, crashitem = pending[0]  # xdist's own rule: the first unfinished test is the one running
            workload[scope][crashitem] = True
            for sc, unit in workload.items():
                if not all(unit.values()):
                    self.workqueue[sc] = unit
            for other in self.assigned_work:
                self._reschedule(other)
            return crashitem

        def _reschedule(self, node: Any) -> None:
            """As xdist's, but a node is given units until it holds at least 2 pending tests (or the queue is
            empty): a worker holds back its last test until it is sent more work or told to stop, and xdist
            only tops a node up when it finishes a test, so a replacement worker handed one re-queued single
            test waited for more work while the controller waited for that test: a second hang."""
            super()._reschedule(node)
            while (self.workqueue and node in self.assigned_work and not node.shutting_down
                   and self._pending_of(self.assigned_work[node]) < 2):
                self._assign_work_unit(node)

    return CrashSafeLoadFileScheduling(config, log)


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config: pytest.Config, log: Any) -> Any:
    if config.getvalue("dist") != "loadfile":
        return None  # xdist's own scheduler
    try:
        return _crash_safe_loadfile(config, log)
    except ImportError:  # pragma: no cover - an xdist without LoadFileScheduling
        return None
