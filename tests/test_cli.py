"""The `lcv` command-line contract (issue: core), including every bad-argument case."""
from __future__ import annotations

import io
import json
import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

from lcvreport.cli import run
from lcvreport.linear import eigenvalues, rear_displacements, steady_state
from lcvreport.loads import load_vector, one_percent_rule
from lcvreport.model import system_matrices
from lcvreport.presets import PRESETS, load_preset

IN = 0.0254  # m per in, typed here on purpose


def lcv(*argv):
    out = io.StringIO()
    code = run(list(argv), out=out)
    return code, out.getvalue()


def lcv_json(*argv):
    code, text = lcv(*argv, "--json")
    assert code == 0
    return json.loads(text)


def _lcv_executable():
    exe = shutil.which("lcv", path=os.path.dirname(sys.executable))
    assert exe, "the console script lcv is not installed next to the test interpreter"
    return exe


def test_console_script_is_installed_and_answers():
    p = subprocess.run([_lcv_executable(), "eig", "--preset", "aucnat", "--speed-mph", "50", "--json"],
                       capture_output=True, text=True, check=True)
    doc = json.loads(p.stdout)
    assert len(doc["eigenvalues"]) == 12


@pytest.mark.parametrize("preset", PRESETS)
def test_eig_json(preset):
    doc = lcv_json("eig", "--preset", preset, "--speed-mph", "45", "--tire-scale", "0.8")
    lam = np.array([complex(a, b) for a, b in doc["eigenvalues"]])
    # the CLI uses the generalized eigenproblem (S, M); eigenvalues() uses eig(M^-1 S):
    # two numerical routes to the same numbers, equal to rounding (~1e-12)
    np.testing.assert_allclose(lam, eigenvalues(load_preset(preset), 45 * 17.6, 0.8), rtol=1e-10)


def test_matrices_json_in_thesis_units_with_and_without_load():
    doc = lcv_json("matrices", "--preset", "tractor_semitrailer", "--speed-mph", "50")
    assert doc["state"] == ["v1", "r1", "r2", "thetaA"]
    assert "F" not in doc
    M, S = system_matrices(load_preset("tractor_semitrailer"), 880.0)
    np.testing.assert_allclose(doc["M"], M, rtol=1e-15)
    np.testing.assert_allclose(doc["S"], S, rtol=1e-15)
    doc = lcv_json("matrices", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer2,trailer3",
                   "--convention", "thesis")
    np.testing.assert_allclose(np.abs(doc["F"]), [423, 3008, 9156, 2744, 8021, 1354, 3414, 0, 0, 0, 0, 0], atol=1)
    doc_c = lcv_json("matrices", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer2,trailer3")
    np.testing.assert_allclose(np.array(doc_c["F"])[1:], 12 * np.array(doc["F"])[1:], rtol=1e-12)


@pytest.mark.parametrize("convention", ["consistent", "thesis"])
def test_steady_json_in_si(convention):
    train = load_preset("aucnat")
    doc = lcv_json("steady", "--preset", "aucnat", "--speed-mph", "30", "--load",
                   "trailer1,dolly1,trailer2,dolly2,trailer3", "--convention", convention)
    F = load_vector(train, one_percent_rule(train, ["trailer1", "dolly1", "trailer2", "dolly2", "trailer3"]),
                    convention)
    x = steady_state(train, 30 * 17.6, F)
    assert list(doc["state"]) == list(train.state_names)
    assert doc["state"]["v1"] == pytest.approx(x[0] * IN, rel=1e-12)
    assert doc["state"]["r1"] == pytest.approx(x[1], rel=1e-12)
    assert doc["state"]["thetaC"] == pytest.approx(x[9], rel=1e-12)
    y = rear_displacements(train, x[7:]) * IN
    assert list(doc["y"]) == ["y2", "y3", "y4", "y5", "y6"]
    assert doc["y"]["y6"] == pytest.approx(y[-1], rel=1e-12)


def test_default_convention_is_consistent():
    a = lcv_json("steady", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer3")
    b = lcv_json("steady", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer3", "--convention",
                 "consistent")
    assert a == b


def test_human_readable_tables():
    code, text = lcv("eig", "--preset", "aucnat", "--speed-mph", "50")
    assert code == 0 and "zeta" in text and "Re [1/s]" in text
    code, text = lcv("steady", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer3")
    assert code == 0 and "y6" in text and " m " in text
    code, text = lcv("matrices", "--preset", "tractor_semitrailer", "--speed-mph", "50")
    assert code == 0 and "M =" in text


BAD = [
    (["eig", "--preset", "nope", "--speed-mph", "50"], "--preset", "aucnat"),
    (["eig", "--preset", "aucnat", "--speed-mph", "0"], "--speed-mph", "> 0"),
    (["eig", "--preset", "aucnat", "--speed-mph", "-5"], "--speed-mph", "> 0"),
    (["eig", "--preset", "aucnat", "--speed-mph", "fast"], "--speed-mph", "> 0"),
    (["eig", "--preset", "aucnat", "--speed-mph", "inf"], "--speed-mph", "> 0"),
    (["eig", "--preset", "aucnat", "--speed-mph", "50", "--tire-scale", "0"], "--tire-scale", "> 0"),
    (["eig", "--preset", "aucnat", "--speed-mph", "50", "--tire-scale", "-1"], "--tire-scale", "> 0"),
    (["eig", "--preset", "aucnat", "--speed-mph", "50", "--tire-scale", "nan"], "--tire-scale", "> 0"),
    (["steady", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer4"], "--load", "trailer3"),
    (["steady", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer2,,trailer3"], "--load", "trailer1"),
    (["steady", "--preset", "tractor_semitrailer", "--speed-mph", "50", "--load", "trailer2"], "--load", "trailer1"),
    (["matrices", "--preset", "aucnat", "--speed-mph", "50", "--load", "dolly7"], "--load", "dolly1"),
    (["steady", "--preset", "aucnat", "--speed-mph", "50"], "--load", "required"),
    (["steady", "--preset", "aucnat", "--speed-mph", "50", "--load", "trailer3", "--convention", "si"],
     "--convention", "consistent"),
    (["eig", "--speed-mph", "50"], "--preset", "required"),
    (["frobnicate"], "COMMAND", "eig"),
    ([], "COMMAND", "required"),
    (["eig", "--preset", "legal_max", "--speed-mph", "50", "--masses", "unrounded"], "--masses", "aucnat"),
]


@pytest.mark.parametrize("argv, names, valid", BAD)
def test_bad_arguments_exit_nonzero_with_one_line(argv, names, valid, capsys):
    code, out = lcv(*argv)
    err = capsys.readouterr().err
    assert code != 0
    assert out == ""
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert names in lines[0] and valid in lines[0], lines[0]
    assert "Traceback" not in err


def test_bad_argument_through_the_console_script():
    p = subprocess.run([_lcv_executable(), "steady", "--preset", "aucnat", "--speed-mph", "50", "--load", "x"],
                       capture_output=True, text=True)
    assert p.returncode == 2 and p.stdout == ""
    assert len(p.stderr.strip().splitlines()) == 1 and "--load" in p.stderr
