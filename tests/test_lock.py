"""requirements.lock pins every dependency pyproject.toml declares, within its bounds."""

import re
import tomllib

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name

from conftest import REPO


def _lock():
    pins = {}
    for line in (REPO / "requirements.lock").read_text().splitlines():
        m = re.match(r"^([A-Za-z0-9_.\-]+)==([^\s;#]+)", line)
        if m:
            pins[canonicalize_name(m.group(1))] = m.group(2)
    return pins


def test_lock_pins_every_declared_dependency():
    project = tomllib.loads((REPO / "pyproject.toml").read_text())["project"]
    reqs = list(project["dependencies"])
    for extra_reqs in project.get("optional-dependencies", {}).values():  # every extra
        reqs += extra_reqs
    pins = _lock()
    assert len(pins) > len(reqs)  # the transitive closure, not only the direct ones
    for text in reqs:
        req = Requirement(text)
        name = canonicalize_name(req.name)
        assert name in pins, f"{req.name} missing from requirements.lock (run .ci/lock)"
        assert req.specifier.contains(pins[name], prereleases=True), (text, pins[name])
