"""AMPI's database for a mission built on demand (the method's preparation): the mission's
problem (guidance.ampi.mission) solved on its grid by the database study, then a few entries drawn
like the campaign's solved afresh and compared with their AMPI references (the interpolation error
against fresh solves, paper 003 Sec. V; guidance.ampi.accuracy_study), all into the user's cache.
A lock file keeps two processes from building the same database at once (the second waits, then
loads it); a child process (a campaign's worker) only loads it."""
from __future__ import annotations

import contextlib
import fcntl
import json
import multiprocessing
import os
import shutil

from drake_entry.errors import ScenarioError
from drake_entry.guidance.ampi.accuracy_study import AccuracyStudy, accuracy_study, summarise
from drake_entry.guidance.ampi.database_study import DatabaseStudy, build_database
from drake_entry.guidance.ampi.grid import ParameterGrid
from drake_entry.guidance.ampi.mission import (
    DATABASE_FILE,
    PROBLEM_FILE,
    REPORT_FILE,
    MissionDatabase,
    built_database,
    database_folder,
    mission_problem_spec,
    read_built,
)
from drake_entry.guidance.ampi.spec import MISSION_DATABASE

__all__ = ["prepare", "mission_study", "build_mission_database"]


def mission_study(spec, problem_path: str):
    """The DatabaseStudy of the spec's grid on the problem file at ``problem_path``."""
    grid = ParameterGrid.from_steps(dict(spec.grid), int(spec.grid_levels))
    return DatabaseStudy(problem=problem_path, grid=grid.as_dict(), ld_nodes=int(spec.ld_nodes))


@contextlib.contextmanager
def _locked(path: str):
    with open(path, "a") as f:
        fcntl.flock(f, fcntl.LOCK_EX)
        try:
            yield
        finally:
            fcntl.flock(f, fcntl.LOCK_UN)


def build_mission_database(spec, scenario, *, progress: bool = True, workers: int | None = None) -> MissionDatabase:
    """The database of ``scenario``'s mission for the Ampi ``spec``: from the cache, or built
    there first (module docstring)."""
    folder, key, text = database_folder(spec, scenario)
    if multiprocessing.parent_process() is not None:  # a worker, or a script re-imported by one
        try:
            return built_database(spec, scenario)
        except ScenarioError as e:
            raise ScenarioError(f"{e}; this is a child process, which never builds it (a script that starts "
                                f"processes needs `if __name__ == '__main__':`)") from None
    os.makedirs(folder, exist_ok=True)
    with _locked(os.path.join(os.path.dirname(folder), f"{key}.lock")):
        built = read_built(folder)  # by another process while this one waited, or by an earlier run
        if built is not None:
            return built
        problem_path = os.path.join(folder, PROBLEM_FILE)
        with open(problem_path, "w") as f:
            f.write(f"# {mission_problem_spec.__doc__.splitlines()[0]}\n{text}")
        build_dir = os.path.join(folder, "build")
        db, report = build_database(build_dir, mission_study(spec, problem_path), backend="processes",
                                    workers=workers, progress=progress)
        if report["verified"] < db.grid.size:
            missing = [int(i) for i in range(db.grid.size) if not db.verified[i]]
            raise ScenarioError(f"the AMPI database of mission '{scenario.name}' has {report['verified']} of "
                                f"{db.grid.size} cases verified (not: cases {missing[:8]}); their solves are in "
                                f"{build_dir}")
        path = os.path.join(folder, DATABASE_FILE)
        shutil.copyfile(os.path.join(build_dir, "database.npz"), path)
        rows = accuracy_study(os.path.join(folder, "accuracy"),
                              AccuracyStudy(database=path, cases=int(spec.accuracy_cases), seed=0),
                              backend="processes", workers=workers, progress=progress)
        accuracy = summarise(rows)
        with open(os.path.join(folder, REPORT_FILE), "w") as f:
            json.dump({"build": report, "accuracy": accuracy, "fingerprint": key}, f, indent=1, default=float)
        return MissionDatabase(path, folder, report, accuracy, False)


def prepare(scenario, *, progress: bool = True) -> str | None:
    """The Ampi method's preparation (GuidanceMethod.preparation): the mission's database when the
    spec asks for one (``database: mission``); a one-line summary."""
    spec = scenario.guidance
    if spec.database != MISSION_DATABASE:
        return None
    m = build_mission_database(spec, scenario, progress=progress)
    r = m.report
    how = "loaded from the cache" if m.cached else f"built in {r['wall_s']:.0f} s"
    return (f"AMPI database of mission '{scenario.name}': {r['verified']}/{r['cases']} cases verified, {how} "
            f"({m.folder})")
