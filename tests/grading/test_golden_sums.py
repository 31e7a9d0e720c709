"""The golden data's checksums (grading/checks/golden_sums.py): the committed record matches the
committed data, a changed byte or a missing record is found and named, and the grader then
refuses to grade, with the reason, marked for regrade."""
import shutil

import pytest

from grading.checks import golden_sums
from grading.grade import grade
from labkit.harness import GOLDEN, ROOT


def test_the_record_matches_the_golden_data():
    assert golden_sums.problem() is None
    assert golden_sums.RECORD.read_text() == golden_sums.record()


@pytest.fixture
def golden_copy(tmp_path):
    """A copy of the golden data inside the repository tree (the record names files relative
    to it), removed afterwards."""
    copy = ROOT / "build" / f"golden-copy-{tmp_path.name}"
    shutil.copytree(GOLDEN, copy)
    yield copy
    shutil.rmtree(copy)


def test_a_changed_byte_is_named(golden_copy):
    record = golden_copy / "SHA256SUMS"
    record.write_text(golden_sums.record(golden_copy))
    assert golden_sums.problem(golden_copy, record) is None
    pfm = golden_copy / "cornell" / "golden.pfm"
    data = bytearray(pfm.read_bytes())
    data[-1] ^= 1
    pfm.write_bytes(bytes(data))
    reason = golden_sums.problem(golden_copy, record)
    assert reason and "cornell/golden.pfm does not match its recorded checksum" in reason
    record.unlink()
    assert "is missing" in golden_sums.problem(golden_copy, record)


def test_the_grader_refuses_golden_data_not_as_recorded(lab01_ref, tmp_path, monkeypatch):
    monkeypatch.setattr(golden_sums, "problem", lambda: "reference/golden/cornell/golden.pfm "
                        "does not match its recorded checksum (stand-in)")
    results = grade("01", lab01_ref, tmp_path, trusted=True)
    assert results["score"] == 0
    assert "golden data that is not as recorded" in results["output"]
    assert all(t["extra_data"]["regrade"] for t in results["tests"])
