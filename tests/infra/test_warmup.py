"""`asymslide warmup`: every compiled entry point is called once, and the two log lines say so."""

from __future__ import annotations

from asymslide.cli import main
from asymslide.warmup import _calls, compile_kernels


def test_compile_kernels_logs_start_and_ready() -> None:
    lines: list[str] = []
    seconds = compile_kernels(log=lines.append)
    assert len(lines) == 2
    assert "compiling kernels" in lines[0]
    assert lines[1].startswith("asymslide: kernels ready in ") and seconds >= 0


def test_every_warmup_call_returns_finite_numbers() -> None:
    import numpy as np

    for what, call in _calls():
        out = call()
        values = out if isinstance(out, tuple) else (out,)
        first = np.asarray(getattr(values[0], "growth", getattr(values[0], "z", values[0])))
        assert first.size and np.isfinite(np.asarray(first, dtype=complex)).any(), what


def test_warmup_command_exits_zero(capsys) -> None:
    assert main(["warmup"]) == 0
    assert "kernels ready" in capsys.readouterr().out
