"""`opnav approach|landing --config FILE --set KEY=VALUE`: overlays on the defaults, one
validation (schema + physics checks), errors naming the flag; `python -m opnav`."""

import json
import subprocess
import sys

import pytest
import yaml

from conftest import REPO
from opnav.cli import main

QUICK = str(REPO / "config" / "quick.yaml")
CASE = ["approach", "--seeds", "2", "--variant", "roll"]


def _run(capsys, argv):
    code = main(argv)
    out = capsys.readouterr()
    return code, (json.loads(out.out) if code == 0 else None), out.err


def test_subcommand_config_is_the_top_level_overlay(capsys):
    c1, top, _ = _run(capsys, ["--config", QUICK, *CASE])
    c2, sub, _ = _run(capsys, [*CASE, "--config", QUICK])
    assert c1 == c2 == 0
    assert top == sub
    assert sub["segments"]["N0"] == yaml.safe_load(open(QUICK))["approach"]["segments"]["N0"]


def test_set_reaches_any_key_and_changes_the_result(capsys):
    _, base, _ = _run(capsys, [*CASE, "--config", QUICK])
    code, new, err = _run(capsys, [*CASE, "--config", QUICK, "--set", "approach.segments.N=25",
                                   "--set", "approach.segments.L=8",
                                   "--set", "approach.camera.sigma3_px=[0.5, 0.5, 1.0]"])
    assert code == 0, err
    assert (new["segments"]["N"], new["segments"]["L"]) == (25, 8)
    assert new["pixel_sigma3_px"] == [0.5, 0.5, 1.0]
    assert new["crlb_arcsec"]["tx"] > base["crlb_arcsec"]["tx"]        # noisier pixels: a larger bound
    # the subcommand's own flag wins over --set
    _, flag, _ = _run(capsys, [*CASE, "--config", QUICK, "--set", "approach.segments.N=25",
                               "--set", "approach.segments.L=8", "--N", "50", "--L", "4"])
    assert flag["segments"]["N"] == 50 and flag["crlb_arcsec"] == base["crlb_arcsec"]


@pytest.mark.parametrize("sets, fragment", [
    (["approach.camera.ifov_arcsec=-1"], "--set approach.camera.ifov_arcsec=-1: invalid config key 'approach.camera.ifov_arcsec'"),
    (["approach.camera.ifov=10"], "--set approach.camera.ifov: no config key 'approach.camera.ifov'"),
    (["nosuch.key=1"], "no config key 'nosuch.key'"),
    (["approach.segments.N"], "expected KEY.PATH=VALUE"),
    (["approach.segments.N=[1,"], "--set approach.segments.N: the value '[1,' is not valid YAML"),
    (["approach.segments.N=many"], "--set approach.segments.N=many: invalid config key 'approach.segments.N'"),
])
def test_bad_set_is_refused_naming_the_flag_and_key(capsys, sets, fragment):
    argv = [*CASE, "--config", QUICK]
    for s in sets:
        argv += ["--set", s]
    code, _, err = _run(capsys, argv)
    assert code == 2
    assert fragment in err, err


def test_landing_takes_overlays_too(capsys):
    code, out, err = _run(capsys, ["landing", "--config", QUICK, "--set", "landing.camera.fov_deg=75",
                                   "--method", "svd", "--seed", "1"])
    assert code == 0, err
    assert out["method"] == "svd"
    code, _, err = _run(capsys, ["landing", "--set", "landing.camera.fov_deg=400"])
    assert code == 2 and "--set landing.camera.fov_deg" in err


def test_python_dash_m_opnav():
    proc = subprocess.run([sys.executable, "-m", "opnav", "landing", "--help"], capture_output=True, text=True)
    assert proc.returncode == 0
    assert "--set KEY.PATH=VALUE" in proc.stdout and "--config FILE" in proc.stdout
