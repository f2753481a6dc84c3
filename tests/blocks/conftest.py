"""Fixtures of the framework's tests."""

from __future__ import annotations

import pytest

from .kernel_library import build


@pytest.fixture(scope="module")
def library(tmp_path_factory):
    """The compiled test kernels (``kernel_library``); the test skips without a C compiler."""
    lib = build(tmp_path_factory.mktemp("kernels") / "leak.so")
    if lib is None:
        pytest.skip("no C compiler to build the test kernels")
    return lib
