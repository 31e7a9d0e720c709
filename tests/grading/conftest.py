"""The grader's tests' fixtures: `mode` runs a test once in each sandbox, bubblewrap and the
user sandbox where namespaces are refused (as in Docker's default seccomp profile), as
GRADING_SANDBOX picks them."""
import os

import pytest

from labkit import sandbox
from labkit.harness import ROOT


@pytest.fixture(params=[sandbox.BUBBLEWRAP, sandbox.USER])
def mode(request, monkeypatch):
    """This process's runs in one sandbox, picked as GRADING_SANDBOX picks it."""
    if request.param == sandbox.USER and os.geteuid() != 0:
        pytest.skip("the user sandbox needs the grader to run as root")
    monkeypatch.setenv("GRADING_SANDBOX", request.param)
    monkeypatch.setattr(sandbox, "_probe_result", [])
    monkeypatch.setattr(sandbox, "_isolation", [])
    reason = sandbox.probe()
    if reason and request.param == sandbox.BUBBLEWRAP:  # a container refusing namespaces
        pytest.skip(f"bubblewrap cannot run here: {reason}")
    assert reason is None and sandbox.isolation() == request.param, reason
    if request.param == sandbox.USER:
        sandbox.hide_from_sandbox(ROOT)
    return request.param
