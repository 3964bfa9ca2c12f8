"""6-UPS answers stay those of the code before the constraint table.

``test/golden/ups_example.npz`` was computed by ``test/golden/make_ups_golden.py`` run on a
checkout of commit 3c6da1e (see its docstring): the packaged example and the same machine with
a leg diameter, 4,000 seeded poses, projected workspaces (both methods), orientation workspaces,
torsion ranges at the paper's two positions, and a 39-move toolpath. Verdicts and integer
answers must be identical, margins and boundaries within 1e-12.

Two entries were replaced since, by today's code: ``example_off_volume`` and
``diameter_off_volume`` (ψmin, ψmax, volume of the orientation workspace at (0.2, 0.2, −0.95) m).
The search of the torsion extremes at 3c6da1e, a four-direction compass search, stalled on the
ridge where two constraints meet: ψmax 2.08e-5 rad (21 tolerances) and ψmin 1.9e-6 rad short of
the poses it now reaches in 16 directions, each extreme with a witness pose that ``check`` finds
reachable (issue #35 item 9; test_workspaces.py samples beyond the extremes).
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

GOLDEN = Path(__file__).parent / "golden"


def _maker():
    spec = importlib.util.spec_from_file_location("make_ups_golden", GOLDEN / "make_ups_golden.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def stored_and_now():
    stored = dict(np.load(GOLDEN / "ups_example.npz"))
    return stored, _maker().answers()


def test_every_golden_array_is_computed(stored_and_now):
    stored, now = stored_and_now
    assert sorted(stored) == sorted(now)


def test_ups_answers_identical_to_before(stored_and_now):
    stored, now = stored_and_now
    for key, expected in stored.items():
        got = np.asarray(now[key])
        assert got.shape == expected.shape, key
        if expected.dtype.kind in "biuU":
            np.testing.assert_array_equal(got, expected, err_msg=key)
        else:
            np.testing.assert_allclose(got, expected, rtol=0.0, atol=1e-12, err_msg=key)
