"""What ``hierhand fmu info`` shows of an FMU, read without running its code."""

from __future__ import annotations

import os
from fractions import Fraction

import pytest

from blocks.fmu import description
from blocks.fmu.description import FMUInfoError, describe_fmu, step_of


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


@pytest.mark.parametrize("text, step", [("0.1", Fraction(1, 10)), ("1e-3", Fraction(1, 1000)), (" 2 ", Fraction(2)),
                                        ("0." + "1" * 5000, Fraction("0.1111111111111111"))])
def test_a_step_attribute_is_the_decimal_of_the_double_it_is(text, step):
    """stepSize is an xs:double: 5000 digits are the double's 17 (a schedule of the exact
    decimal would have a base tick of 1e-5000 s)."""
    assert step_of(text) == step


@pytest.mark.parametrize("text, why", [("1e308", "out of range"), ("1e-308", "out of range"),
                                       ("1e999999999", "not a positive finite number"), ("-1", "not a positive"),
                                       ("soon", "not a number")])
def test_a_step_attribute_out_of_range_is_refused_quickly(text, why):
    """1e999999999 as an exact Fraction would take forever to compute."""
    with pytest.raises(ValueError, match=why):
        step_of(text)


def test_fmu_info_shows_unusable_steps_and_cuts_long_texts(fmus):
    fixed = describe_fmu(fmus.with_fixed_step(3, "1e308", "fixed_huge.fmu"))
    assert "fixed internal step: 1e308 (not usable: out of range (1e-12 s to 1e9 s))" in fixed
    long = describe_fmu(fmus.make("long_step.fmu", fmus.xml2.replace('stepSize="0.1"', 'stepSize="0.' + "1" * 5000 + '"')))
    assert "step 0." + "1" * 38 + "..." in long and "1" * 60 not in long


def test_fmu_info_says_what_a_path_that_is_not_an_fmu_file_is(tmp_path):
    os.mkfifo(tmp_path / "pipe.fmu")
    with pytest.raises(FMUInfoError, match=r"FMU '.*pipe\.fmu' cannot be read as an FMU: it is a FIFO \(named pipe\), "
                                           "not a regular file"):
        describe_fmu(tmp_path / "pipe.fmu")
    with pytest.raises(FMUInfoError, match="it is a device, not a regular file"):
        describe_fmu("/dev/zero")
    with pytest.raises(FMUInfoError, match="is a folder; give the path of the .fmu file"):
        describe_fmu(tmp_path)
    with pytest.raises(FMUInfoError, match="FMU file not found"):
        describe_fmu(tmp_path / "missing.fmu")


def test_an_unreadable_fmu_file_says_permission_denied(tmp_path, monkeypatch):
    """Not 'not an FMU': the file may well be one (as root, a file's mode does not stop
    reading it, so the refusal is the operating system's answer, made here)."""
    path = tmp_path / "locked.fmu"
    path.write_bytes(b"PK")

    def refused(p):
        raise PermissionError(13, "Permission denied", str(p))

    monkeypatch.setattr(description, "open_regular", refused)
    with pytest.raises(FMUInfoError, match=r"FMU '.*locked\.fmu' cannot be read: permission denied \(check the "
                                           "permissions of the file and of its folders\\)"):
        describe_fmu(path)


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads files whatever their mode")
def test_a_file_without_read_permission_says_so(tmp_path):
    path = tmp_path / "locked.fmu"
    path.write_bytes(b"PK")
    path.chmod(0)
    with pytest.raises(FMUInfoError, match="cannot be read: permission denied"):
        describe_fmu(path)
