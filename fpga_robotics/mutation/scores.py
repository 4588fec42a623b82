"""Mutation scores from the judges' verdicts (pure functions: the report and the tests share
them).

- unit score: the mutants the unit judge catches, over all mutants;
- robot score: the mutants the robot judge catches, over the mutants the unit judge catches
  (a mutant no frame can show cannot be asked of a scenario);
- blind spots: caught by the unit judge, missed by every scenario.
"""

from collections import defaultdict

__all__ = ["blind_spots", "by_module", "robot_score", "unit_score"]


def _ratio(n, d):
    return None if d == 0 else n / d


def unit_score(unit):
    """``{"total", "caught", "equivalent", "score"}`` from ``{index: caught}``."""
    caught = sum(1 for c in unit.values() if c)
    return {
        "total": len(unit),
        "caught": caught,
        "equivalent": len(unit) - caught,
        "score": _ratio(caught, len(unit)),
    }


def robot_score(unit, robot):
    """``{"judged", "caught", "score"}``: of the unit-caught mutants (``unit``:
    ``{index: caught}``), how many the robot judge (``robot``: ``{index: caught}``, for the
    mutants it ran) catches. Mutants the robot judge has not run yet are left out."""
    judged = [i for i, c in unit.items() if c and i in robot]
    caught = sum(1 for i in judged if robot[i])
    return {"judged": len(judged), "caught": caught, "score": _ratio(caught, len(judged))}


def blind_spots(unit, robot):
    """The indices caught by the unit judge and run, but not caught, by the robot judge."""
    return sorted(i for i, c in unit.items() if c and i in robot and not robot[i])


def by_module(mutants, unit, robot=None):
    """``{module: {"total", "unit_caught", "robot_caught"}}`` (``mutants``: ``Mutant``s)."""
    robot = robot or {}
    rows = defaultdict(lambda: {"total": 0, "unit_caught": 0, "robot_caught": 0})
    for m in mutants:
        row = rows[m.module or "top"]
        row["total"] += 1
        row["unit_caught"] += bool(unit.get(m.index))
        row["robot_caught"] += bool(unit.get(m.index) and robot.get(m.index))
    return dict(sorted(rows.items()))
