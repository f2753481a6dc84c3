"""The sweep command's summary line says where the points ran, counting each place once."""

from __future__ import annotations

import pytest

from blocks.cli.sweep import where_ran
from blocks.sweep.runner import SweepReport


@pytest.mark.parametrize("ran, workers, local, text", [
    (0, 0, 0, ""),
    (5, 0, 0, " in this process"),
    (16, 0, 16, " in a local process (too little work for a cluster to pay off)"),
    (20, 2, 0, " on 2 Dask workers"),
    (20, 1, 0, " on 1 Dask worker"),
    (20, 2, 20, " in a local process, all before the cluster of 2 Dask workers was ready"),
    (20, 2, 6, ": 14 on 2 Dask workers, 6 in a local process while the cluster started"),
])
def test_where_the_points_ran(ran, workers, local, text):
    assert where_ran(SweepReport(ran=ran, workers=workers, local=local)) == text
