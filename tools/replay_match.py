"""Which of a live node's solutions may differ from `gnss_ins replay`'s of the same inputs.

DDS orders the samples of one writer only: a GNSS message may reach the node after IMU
samples stamped later. The engine then rolls back and applies it, so the solutions it
published before the message arrived lack it, and only those. Each differing solution must
lie in a run that begins at the first solution after a measurement's stamp and ends before
the next measurement's; there are at most as many runs as the node counted late
measurements (`late_measurements` on /diagnostics). The rule of
tests/odometry_support's `assert_live_matches_replay`, for the Python peers.

Plain Python: shared by the Cyclone DDS and the Jazzy peers.
"""

import bisect
import math


def late_runs(solutions, measurement_s):
    """`solutions`: (stamp s, differs from replay) in stamp order; `measurement_s`: the
    stamps of the measurements sent. Returns the number of runs of differing solutions
    that follow a measurement, and the stamps of differing solutions that follow none."""
    measurement_s = sorted(measurement_s)
    runs, misplaced = 0, []
    previous_s, run_ends_by = -math.inf, None
    for t, differs in solutions:
        before, previous_s = previous_s, t
        if not differs:
            run_ends_by = None
            continue
        if run_ends_by is not None:
            if t > run_ends_by:
                misplaced.append(t)
            continue
        at = bisect.bisect_left(measurement_s, before)
        if at < len(measurement_s) and measurement_s[at] < t:
            runs += 1
            run_ends_by = measurement_s[at + 1] if at + 1 < len(measurement_s) else math.inf
        else:
            misplaced.append(t)
    return runs, misplaced


def check_late_runs(checks, what, solutions, measurement_s, late):
    """Checks `solutions` against the rule with the node's count of late measurements;
    returns the number of runs."""
    runs, misplaced = late_runs(solutions, measurement_s)
    checks.that(not misplaced,
                f'{what}: solutions at {misplaced[:5]} s differ from replay and follow no '
                'late measurement')
    checks.that(runs <= late, f'{what}: {runs} runs differ from replay, {late} late measurements')
    return runs
