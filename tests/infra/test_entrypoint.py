"""The Docker image's entrypoint (docker/entrypoint.sh) on this machine, without Docker: as root it hands a root-owned
atlas folder to the app user or runs as the owner of a user's folder, and never runs the command as root; started as
another user it reports a folder it cannot write, and gives that user a writable copy of numba's cache (numba uses
no cache directory it cannot write). .ci/docker-smoke checks the same inside the image."""

from __future__ import annotations

import os
import shutil
import stat
import subprocess
import tempfile
from collections.abc import Iterator
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
APP_UID = 10001
OTHER_UID = 12345

pytestmark = pytest.mark.skipif(os.geteuid() != 0 or shutil.which("setpriv") is None,
                                reason="needs root and util-linux's setpriv, as the image has")


@pytest.fixture
def place() -> Iterator[Path]:
    """A folder every uid can enter (pytest's tmp_path is root's alone), with a copy of the entrypoint, an atlas
    folder and numba's cache as the image has it (the app user's)."""
    top = Path(tempfile.mkdtemp(prefix="asymslide-entrypoint-"))
    try:
        top.chmod(0o755)
        shutil.copy(ROOT / "docker" / "entrypoint.sh", top / "entrypoint")
        (top / "entrypoint").chmod(0o755)
        cache = top / "numba-cache" / "model_x"
        cache.mkdir(parents=True)
        (cache / "kernel.nbi").write_text("index")
        for path in (top / "numba-cache", cache, cache / "kernel.nbi"):
            os.chown(path, APP_UID, APP_UID)
        (top / "tmp").mkdir(mode=0o1777)
        (top / "tmp").chmod(0o1777)
        yield top
    finally:
        shutil.rmtree(top)


def _run(place: Path, atlases: Path, command: str, *, as_uid: int | None = None) -> subprocess.CompletedProcess:
    env = {"PATH": os.environ["PATH"], "ASYMSLIDE_ATLAS_DIR": str(atlases),
           "NUMBA_CACHE_DIR": str(place / "numba-cache"), "TMPDIR": str(place / "tmp"), "HOME": "/root"}
    cmd = [str(place / "entrypoint"), "sh", "-c", command]
    if as_uid is not None:  # what docker run --user does
        cmd = ["setpriv", f"--reuid={as_uid}", f"--regid={as_uid}", "--clear-groups", "--", *cmd]
        env["HOME"] = "/"
    return subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=60)


REPORT = 'echo "$(id -u) $HOME $NUMBA_CACHE_DIR"'


def test_a_root_owned_folder_is_given_to_the_app_user(place: Path) -> None:
    atlases = place / "atlases"  # what docker run -v makes of a folder that did not exist: root's
    atlases.mkdir()
    run = _run(place, atlases, REPORT + " && touch $ASYMSLIDE_ATLAS_DIR/written")
    assert run.returncode == 0, run.stderr
    uid, home, cache = run.stdout.split()
    assert uid == str(APP_UID) and cache == str(place / "numba-cache")  # the image's cache: the app user's own
    # the app user's home in the image; on this machine, which has no such user, a temporary one
    assert home == "/home/asymslide" if Path("/home/asymslide").is_dir() else home.startswith(str(place / "tmp"))
    assert atlases.stat().st_uid == APP_UID and (atlases / "written").stat().st_uid == APP_UID
    assert "given to the app user (uid 10001)" in run.stderr


def test_a_missing_folder_is_made_for_the_app_user(place: Path) -> None:
    run = _run(place, place / "new" / "atlases", REPORT)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split()[0] == str(APP_UID) and (place / "new" / "atlases").stat().st_uid == APP_UID


def test_a_users_folder_stays_theirs(place: Path) -> None:
    atlases = place / "atlases"
    atlases.mkdir()
    os.chown(atlases, OTHER_UID, OTHER_UID)
    run = _run(place, atlases, REPORT + " && touch $ASYMSLIDE_ATLAS_DIR/written && cat $NUMBA_CACHE_DIR/*/kernel.nbi")
    assert run.returncode == 0, run.stderr
    uid, home, cache, copied = run.stdout.split()
    assert uid == str(OTHER_UID) and (atlases / "written").stat().st_uid == OTHER_UID
    assert f"belongs to uid {OTHER_UID}" in run.stderr
    # HOME and numba's cache: writable copies for a uid the image does not know
    assert home.startswith(str(place / "tmp")) and os.stat(home).st_uid == OTHER_UID
    assert cache == str(place / "tmp" / f"asymslide-numba-cache-{OTHER_UID}") and copied == "index"
    assert atlases.stat().st_uid == OTHER_UID  # not taken over


def test_another_user_is_told_when_the_folder_is_not_writable(place: Path) -> None:
    atlases = place / "atlases"
    atlases.mkdir()
    os.chown(atlases, APP_UID, APP_UID)  # the image's own /atlases, and docker run --user 12345
    run = _run(place, atlases, REPORT, as_uid=OTHER_UID)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split()[0] == str(OTHER_UID)
    assert f"is not writable by uid {OTHER_UID}" in run.stderr and "cannot compute the default atlas" in run.stderr
    assert atlases.stat().st_uid == APP_UID and stat.S_IMODE(atlases.stat().st_mode) == 0o755  # nothing changed


def test_the_app_user_keeps_the_images_cache(place: Path) -> None:
    atlases = place / "atlases"
    atlases.mkdir()
    os.chown(atlases, APP_UID, APP_UID)
    run = _run(place, atlases, REPORT, as_uid=APP_UID)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split()[2] == str(place / "numba-cache") and run.stderr == ""


def test_the_command_gets_the_exit_code_and_the_pid(place: Path) -> None:
    """exec all the way: the command replaces the entrypoint (PID 1 in the container gets docker stop's SIGTERM)."""
    atlases = place / "atlases"
    atlases.mkdir()
    proc = subprocess.Popen([str(place / "entrypoint"), "sh", "-c", "echo $$; exit 7"], stdout=subprocess.PIPE,
                            text=True, env={"PATH": os.environ["PATH"], "ASYMSLIDE_ATLAS_DIR": str(atlases),
                                            "TMPDIR": str(place / "tmp")})
    out, _ = proc.communicate(timeout=60)
    assert proc.returncode == 7 and int(out) == proc.pid
