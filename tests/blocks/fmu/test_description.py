"""What ``hierhand fmu info`` shows of an FMU, read without running its code."""

from __future__ import annotations

import pytest

from blocks.fmu.description import FMUInfoError, describe_fmu


def test_fmu_info_shows_the_step_rules(fmus):
    assert "fixed internal step: 0.04 s (informative)" in describe_fmu(fmus.with_fixed_step(3, "0.04", "fixed_info.fmu"))
    assert "fixed internal step" not in describe_fmu(fmus.fmi3)
    assert "communication step: fixed" not in describe_fmu(fmus.fmi3)
    fixed = fmus.make("fixed_comm.fmu", fmus.xml2.replace('canHandleVariableCommunicationStepSize="true"', ""))
    assert "communication step: fixed (canHandleVariableCommunicationStepSize is false)" in describe_fmu(fixed)


def test_fmu_info_lists_interfaces_experiment_and_variables(fmus, tmp_path):
    text = describe_fmu(fmus.fmi2)
    assert "FMI 2.0" in text and "co-simulation (model identifier" in text
    assert "step 0.1" in text
    for name in ("u", "y", "z[1]", "z[2]", "a"):
        assert f"\n    {name} " in text
    assert "input" in text and "output" in text and "parameter" in text
    bogus = tmp_path / "bogus.fmu"
    bogus.write_text("not a zip")
    with pytest.raises(FMUInfoError, match="not a readable zip"):
        describe_fmu(bogus)
