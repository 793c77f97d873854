"""Freed memory kept for the next design (screwkit.common.memory): a design-search evaluation process reuses the pages
it freed instead of faulting in new ones.

Each check runs in fresh processes, since the setting is the whole process's: the same allocations (arrays of 1, 3
and 40 MiB, made and freed three times, as a design's chunks are) counted in minor page faults, with the setting and
without it. Without it glibc hands such blocks back to the system and each new one is faulted in again, so the
comparison fails if the setting stops being made.
"""

from __future__ import annotations

import json
import platform
import subprocess
import sys
import textwrap

import pytest

pytestmark = pytest.mark.skipif(platform.libc_ver()[0] != "glibc",
                                reason="the setting is glibc's mallopt; elsewhere keep_freed_memory does nothing")

FAULTS = textwrap.dedent("""
    import resource

    import numpy as np


    def faults() -> int:
        '''Minor page faults of making and freeing arrays of 1, 3 and 40 MiB three times, after a first time.'''
        sizes = [mib * (1 << 20) // 8 for mib in (1, 3, 40)]
        for size in sizes:
            np.ones(size).sum()
        before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
        for _ in range(3):
            for size in sizes:
                np.ones(size).sum()
        return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
""")


def _run(tmp_path, code: str) -> dict:
    (tmp_path / "faults_probe.py").write_text(FAULTS)
    completed = subprocess.run([sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True,
                               cwd=tmp_path, env={"PYTHONPATH": str(tmp_path), "PATH": "/usr/bin:/bin"},
                               timeout=300)
    assert completed.returncode == 0, completed.stderr
    return json.loads(completed.stdout)


def test_kept_memory_is_reused_without_page_faults(tmp_path):
    result = _run(tmp_path, """
        import json
        from faults_probe import faults
        plain = faults()
        from screwkit.common.memory import keep_freed_memory
        kept = keep_freed_memory()
        print(json.dumps({"plain": plain, "kept": kept, "after": faults()}))
    """)
    assert result["kept"] is True
    assert result["plain"] >= 200, result  # without it the blocks come back as new pages (the comparison can fail)
    assert result["after"] <= 20, result


def test_design_evaluation_processes_keep_freed_memory(tmp_path):
    """The initializer the local evaluation pool starts its processes with (spawned, as a search spawns them), against
    the one that only ties them to their parent."""
    result = _run(tmp_path, """
        import json, multiprocessing, os
        from concurrent.futures import ProcessPoolExecutor
        from faults_probe import faults
        from screwkit.studies.design import evaluations

        counts = {}
        for name in ("_start_worker", "_end_with_parent"):
            with ProcessPoolExecutor(1, mp_context=multiprocessing.get_context("spawn"),
                                     initializer=getattr(evaluations, name), initargs=(os.getpid(),)) as pool:
                counts[name] = pool.submit(faults).result()
        print(json.dumps(counts))
    """)
    assert result["_end_with_parent"] >= 200, result
    assert result["_start_worker"] <= 20, result


def test_a_search_evaluates_in_processes_that_keep_freed_memory(tmp_path):
    """The pool a local search evaluates its designs in (a small planar study's first generation): its processes
    fault in no new pages for a design's arrays."""
    result = _run(tmp_path, """
        import json
        import numpy as np
        from faults_probe import faults
        from screwkit.studies.design.evaluations import Evaluations
        from screwkit.studies.design.families import family
        from screwkit.studies.design.objectives import disc_region
        from screwkit.studies.design.optimise import Study
        from screwkit.studies.tasks import Execution

        chosen = family("planar_rrr", 3)
        study = Study(chosen, disc_region(0.3, 0.1, 30.0), ("area",), free=("base_radius",), budget=2)
        evaluations = Evaluations(study, None, Execution())
        try:
            metrics = evaluations(np.array([[0.5], [0.6]]))
            counts = [evaluations.pool.submit(faults).result() for _ in range(2)]
        finally:
            evaluations.close()
        print(json.dumps({"designs": len(metrics), "counts": counts}))
    """)
    assert result["designs"] == 2
    assert max(result["counts"]) <= 20, result
