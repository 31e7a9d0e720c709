"""labkit/boxes.py on its own: the users sandboxed runs are drawn from, and the folder that
keeps the count."""
import os

import pytest

from labkit import boxes


@pytest.fixture
def state(tmp_path, monkeypatch):
    """The count kept in a folder of this test's (root's, as the grader's is)."""
    if os.geteuid() != 0:
        pytest.skip("the count's folder must be root's")
    folder = tmp_path / "state"
    monkeypatch.setattr(boxes, "STATE_FOLDERS", (str(folder),))
    return folder


def test_no_id_is_drawn_twice(state):
    drawn = [boxes.new_box() for _ in range(50)]
    assert all(fresh for _, fresh in drawn), drawn
    ids = [box for box, _ in drawn]
    assert len({uid for uid, _ in ids}) == 50 and all(u == g for u, g in ids), ids
    assert all(uid in boxes.pool() for uid, _ in ids), ids


def test_an_id_that_came_round_is_not_fresh(state, monkeypatch):
    """Once the pool is spent the counter starts again, and those boxes are reset first."""
    monkeypatch.setattr(boxes, "POOL", range(boxes.POOL.start, boxes.POOL.start + 3))
    drawn = [boxes.new_box() for _ in range(5)]
    assert [box[0] - boxes.POOL.start for box, _ in drawn] == [0, 1, 2, 0, 1], drawn
    assert [fresh for _, fresh in drawn] == [True, True, True, False, False], drawn


def test_a_namespace_of_65536_ids_draws_from_the_fallback_skipping_accounts(state, monkeypatch):
    """A rootless container maps 0-65535 only: ids come from FALLBACK_POOL, never one an
    account or group holds."""
    monkeypatch.setattr(boxes, "_mapped", lambda path: [range(0, 65536)])
    held = {boxes.FALLBACK_POOL.start, boxes.FALLBACK_POOL.start + 1}
    monkeypatch.setattr(boxes, "_taken", lambda ident: ident in held)
    assert boxes.pool() == boxes.FALLBACK_POOL
    assert boxes.new_box()[0][0] == boxes.FALLBACK_POOL.start + 2


def test_no_pool_is_one_line(monkeypatch):
    monkeypatch.setattr(boxes, "_mapped", lambda path: [range(0, 1000)])
    with pytest.raises(OSError) as e:
        boxes.new_box()
    assert "maps neither" in str(e.value) and "\n" not in str(e.value)


def test_a_count_folder_others_may_change_is_refused(state):
    """A folder another user made or may write would let that user choose the next box."""
    state.mkdir(mode=0o777)
    state.chmod(0o777)
    with pytest.raises(OSError) as e:
        boxes.new_box()
    assert "root's alone" in str(e.value), e.value
