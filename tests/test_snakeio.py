"""Job plumbing that users meet when something goes wrong: a failing job's
traceback lands in its rule's log; a truncated intermediate is reported with its
name and the command that rebuilds it."""

import numpy as np
import pytest

from opnav.landing import montecarlo
from opnav.core.snakeio import CorruptIntermediate, load_pickle, save_pickle, script_context, stand_in


def test_failing_job_writes_traceback_to_its_log(tmp_path):
    log = tmp_path / "logs" / "job.log"
    smk = stand_in(log=[str(log)], config={})
    smk.rule = "demo_rule"
    with pytest.raises(SystemExit) as err:
        with script_context(smk) as logger:
            logger.info("starting")
            raise np.linalg.LinAlgError("Matrix is not positive definite")
    msg = str(err.value.code)
    assert msg.startswith("demo_rule failed: LinAlgError: Matrix is not positive definite")
    assert str(log) in msg and "\n" not in msg
    text = log.read_text()
    assert "starting" in text and "Traceback" in text and "LinAlgError" in text


def test_interrupt_is_not_swallowed(tmp_path):
    smk = stand_in(log=[str(tmp_path / "x.log")], config={})
    with pytest.raises(KeyboardInterrupt):
        with script_context(smk):
            raise KeyboardInterrupt


@pytest.mark.parametrize("cut", [0, 10, -20])
def test_truncated_intermediates_are_named(tmp_path, cut):
    npz, pkl = tmp_path / "chunk.npz", tmp_path / "mc.pkl"
    montecarlo.save(npz, montecarlo.MonteCarlo(t=np.arange(50.0)), "depth")
    save_pickle(pkl, {"x": np.arange(50.0)})
    assert montecarlo.load(npz).t[-1] == 49.0 and load_pickle(pkl)["x"][-1] == 49.0
    for path, loader in ((npz, montecarlo.load), (pkl, load_pickle)):
        data = path.read_bytes()
        path.write_bytes(data[:cut] if cut else b"")
        with pytest.raises(CorruptIntermediate) as err:
            loader(path)
        assert str(path) in str(err.value) and f"snakemake --cores 2 --force {path}" in str(err.value)


def test_atomic_writers_leave_no_partial_file(tmp_path, monkeypatch):
    """A writer that dies mid-way leaves neither a partial output nor a temporary file."""
    import pickle

    def die(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(pickle, "dump", die)
    with pytest.raises(KeyboardInterrupt):
        save_pickle(tmp_path / "a.pkl", {"x": 1})
    monkeypatch.setattr(np, "savez_compressed", die)
    with pytest.raises(KeyboardInterrupt):
        montecarlo.save(tmp_path / "b.npz", montecarlo.MonteCarlo(t=np.zeros(3)), "depth")
    assert list(tmp_path.iterdir()) == []


def test_chunk_names_cover_any_number_of_chunks():
    """More than 999 chunks (and run indices past 9999) still match the rules' wildcard."""
    import re

    from opnav.landing.montecarlo import CHUNK_PATTERN, chunk_label, chunk_runs, chunks

    parts = chunks(12_345, 1)
    assert len(parts) == 12_345
    labels = [chunk_label(c) for c in parts]
    assert len(set(labels)) == len(labels)
    for c, lab in zip(parts[::997] + parts[-2:], labels[::997] + labels[-2:]):
        assert re.fullmatch(CHUNK_PATTERN, lab), lab
        assert chunk_runs(lab) == list(c)


def test_intermediate_csv_refuses_a_cut_or_edited_file(tmp_path):
    """A study chunk CSV cut inside its last row still parses with pandas (a NaN column);
    the stamp (rows, checksum) refuses it, and an edited value, naming the file and the
    rebuild command, as a truncated .npz or pickle is refused."""
    import numpy as np
    import pandas as pd

    from opnav.core.snakeio import CorruptIntermediate, load_csv, save_csv

    df = pd.DataFrame({"method": ["depth", "svd"] * 3, "run": np.arange(6),
                       "final_pos_err_m": np.linspace(0.1, 9.9, 6) / 3.0})
    f = tmp_path / "0-5.csv"
    save_csv(f, df)
    back = load_csv(f)
    pd.testing.assert_frame_equal(back, df)
    good = f.read_bytes()
    cut = good[:-9]
    assert len(pd.read_csv(__import__("io").BytesIO(cut.split(b"\n", 1)[1]))) == 6   # pandas alone accepts it
    for bad in (cut, good.replace(b"depth", b"dapth", 1), good.split(b"\n", 1)[1], b""):
        f.write_bytes(bad)
        with pytest.raises(CorruptIntermediate, match=r"0-5\.csv.*snakemake --cores 2 --force"):
            load_csv(f)


def test_intermediate_json_refuses_a_truncated_file(tmp_path):
    from opnav.core.snakeio import CorruptIntermediate, load_json

    f = tmp_path / "s.json"
    f.write_text('{"a": [1, 2, 3], "b": {"c": 1.5}}')
    assert load_json(f) == {"a": [1, 2, 3], "b": {"c": 1.5}}
    f.write_text('{"a": [1, 2, 3], "b": {"c": 1.')
    with pytest.raises(CorruptIntermediate, match=r"s\.json.*--force"):
        load_json(f)


def test_tables_and_summaries_are_read_checked(tmp_path):
    """write_table / write_json leave a checksum sidecar that load_table / load_json check:
    a table cut mid-row or at a row boundary, an edited cell, a summary cut or edited are
    refused naming the file and the rebuild command (issue 46 item 4: A-T1 cut mid-row lost
    5 rows silently). Without a sidecar (a file written by hand) the table is validated:
    a cut mid-row is still refused. Mutation: _checked_text not comparing the checksum
    fails the row-boundary and edit cases."""
    import pandas as pd

    from opnav.core.snakeio import load_json, load_table
    from opnav.core.tables import checksum_path, write_json, write_table

    df = pd.DataFrame({"case": [f"T1-{i:02d}" for i in range(1, 8)], "tx": [0.5 * i for i in range(7)]})
    f = write_table(df, [tmp_path / "A-T1_table1.csv"])[0]
    pd.testing.assert_frame_equal(load_table(f), df)
    good = f.read_bytes()
    lines = good.split(b"\n")
    for bad in (good[:-5], b"\n".join(lines[:4]) + b"\n", good.replace(b"T1-03", b"T1-33")):
        f.write_bytes(bad)
        with pytest.raises(CorruptIntermediate, match=r"A-T1_table1\.csv.*snakemake --cores 2 --force"):
            load_table(f)
    checksum_path(f).unlink()                       # a hand-written table: validated on read
    f.write_bytes(good)
    pd.testing.assert_frame_equal(load_table(f), df)
    f.write_bytes(good[:-5])
    with pytest.raises(CorruptIntermediate, match="cut inside its last row"):
        load_table(f)
    s = tmp_path / "B-summary.json"
    write_json(s, {"a": 1.5, "b": [1, 2]})
    assert load_json(s) == {"a": 1.5, "b": [1, 2]}
    text = s.read_text()
    for bad in (text[: len(text) // 2], text.replace("1.5", "2.5")):
        s.write_text(bad)
        with pytest.raises(CorruptIntermediate, match=r"B-summary\.json.*--force"):
            load_json(s)
