"""The output folder rule (``sailroute.outdir``): checked before the work, written as a set.

A run leaves all its files or none; files listed in the previous run's manifest and not
written again are removed; nothing the tool did not write is ever deleted.
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from sailroute.errors import InputError
from sailroute.outdir import MANIFEST_NAME, check_out_dir, read_manifest, write_output_set
from sailroute.report.files import POLAR_FILE_LABELS, file_label


def writer(files: dict[str, str]):
    """A writer that writes ``files`` (relative path -> text) and returns their paths."""

    def write(d: Path) -> dict[str, Path]:
        out = {}
        for rel, text in files.items():
            p = d / rel
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_text(text)
            out[rel] = p
        return out

    return write


def snapshot(d: Path) -> dict[str, str]:
    return {p.relative_to(d).as_posix(): p.read_text() for p in sorted(d.rglob("*")) if p.is_file()}


def leftovers(*dirs: Path) -> list[str]:
    return [p.name for d in dirs for p in d.iterdir() if "sailroute-tmp" in p.name]


def test_new_folder_gets_the_files_and_a_manifest(tmp_path):
    out = tmp_path / "a" / "b"
    files = write_output_set(out, writer({"plan.json": "1", "s/track.csv": "2"}))
    assert files == {"plan.json": out / "plan.json", "s/track.csv": out / "s" / "track.csv"}
    assert snapshot(out) == {
        "plan.json": "1",
        "s/track.csv": "2",
        MANIFEST_NAME: (out / MANIFEST_NAME).read_text(),
    }
    assert read_manifest(out) == {"plan.json", "s/track.csv"}
    assert leftovers(out, out.parent) == []


def test_rerun_replaces_the_set_and_keeps_the_users_files(tmp_path):
    out = tmp_path / "o"
    write_output_set(out, writer({"plan.json": "old", "route.png": "old", "s/x.csv": "old"}))
    (out / "notes.txt").write_text("mine")
    (out / "s" / "mine.csv").write_text("mine")
    write_output_set(out, writer({"plan.json": "new"}))  # e.g. a --no-plots rerun
    assert snapshot(out) == {
        "plan.json": "new",
        "notes.txt": "mine",
        "s/mine.csv": "mine",
        MANIFEST_NAME: (out / MANIFEST_NAME).read_text(),
    }
    assert read_manifest(out) == {"plan.json"}
    # a folder emptied of the old run's files goes too; one with a user's file stays
    write_output_set(out, writer({"t/y.csv": "1"}))
    write_output_set(out, writer({"plan.json": "again"}))
    assert not (out / "t").exists() and (out / "s" / "mine.csv").read_text() == "mine"


@pytest.mark.parametrize("exc", [RuntimeError("disk on fire"), KeyboardInterrupt()])
def test_a_failure_mid_write_leaves_the_previous_set_and_no_temp_folder(tmp_path, exc):
    out = tmp_path / "o"
    write_output_set(out, writer({"plan.json": "old", "route.png": "old"}))
    (out / "notes.txt").write_text("mine")
    before = snapshot(out)

    def half(d: Path) -> None:
        (d / "plan.json").write_text("new")  # written, then the run dies
        raise exc

    with pytest.raises(type(exc)):
        write_output_set(out, half)
    assert snapshot(out) == before
    assert leftovers(out, tmp_path) == []
    # and into a folder that did not exist: nothing at all is left
    with pytest.raises(type(exc)):
        write_output_set(tmp_path / "new", half)
    assert not (tmp_path / "new").exists() and leftovers(tmp_path) == []


def test_without_a_manifest_only_same_named_files_are_replaced(tmp_path):
    out = tmp_path / "o"
    out.mkdir()
    (out / "route.png").write_text("from an older version, or the user's")
    (out / "plan.json").write_text("old")
    write_output_set(out, writer({"plan.json": "new"}))
    assert (out / "route.png").exists() and (out / "plan.json").read_text() == "new"


def test_a_manifest_cannot_delete_outside_the_folder(tmp_path):
    out = tmp_path / "o"
    out.mkdir()
    victim = tmp_path / "victim.txt"
    victim.write_text("keep")
    (out / MANIFEST_NAME).write_text(
        json.dumps({"files": ["../victim.txt", "/etc/hosts", "ok.txt"]})
    )
    (out / "ok.txt").write_text("old output")
    assert read_manifest(out) == {"ok.txt"}
    write_output_set(out, writer({"plan.json": "1"}))
    assert victim.read_text() == "keep" and not (out / "ok.txt").exists()


def test_check_out_dir_refuses_files_without_creating_anything(tmp_path):
    f = tmp_path / "taken"
    f.write_text("x")
    with pytest.raises(InputError, match="a file of that name exists"):
        check_out_dir(f)
    with pytest.raises(InputError, match=r"'.*taken' is a file, not a folder"):
        check_out_dir(f / "sub" / "out")
    assert check_out_dir(tmp_path / "x" / "y") == tmp_path / "x" / "y"
    assert not (tmp_path / "x").exists()
    with pytest.raises(InputError, match="choose another folder with --out"):
        write_output_set(f, writer({"a": "1"}))


def test_file_labels_name_what_was_written():
    assert file_label("plan", "o/plan.json") == "plan (JSON)"
    assert file_label("wrf10/track", "o/wrf10/track.csv") == "wrf10: track (CSV)"
    assert file_label("comparison_png", "o/comparison.png") == "comparison chart (PNG)"
    assert file_label(None, "o/policy_map.png") == "policy map (PNG)"
    assert file_label(None, "o/summary.json") == "summary (JSON)"
    assert file_label("png", "o/ilca7.png", POLAR_FILE_LABELS) == "polar plot (PNG)"
