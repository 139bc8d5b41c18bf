"""The optional tables `fivebar view` draws beside the trees: `aspects.csv` (modes, certificate and,
when present, the largest circle and square of each aspect), `aspects-adjacency.csv` (the crossings
graph) and `path.csv` (a motion, one configuration per row).

Columns are read by name, so tables of other versions (extra or missing optional columns) work;
a required column that is missing or a cell that is not a number is an InputError naming the
file, the line and the column.
"""

from __future__ import annotations

import math
from pathlib import Path

from fivebar_cli.errors import InputError
from fivebar_cli.io.files import read_csv_table

CIRCLE = ("circle_x", "circle_y", "circle_r")
SQUARE = ("square_x", "square_y", "square_side")
MAX_PATH_ROWS = 200_000


def _number(path: Path, line: int, column: str, text: str, integer: bool = False) -> float | int:
    try:
        value = int(text) if integer else float(text)
    except ValueError:
        kind = "an integer" if integer else "a number"
        raise InputError(str(path), f"line {line} ({column})", f"expected {kind}, got {text!r}") from None
    if not integer and not math.isfinite(value):
        raise InputError(str(path), f"line {line} ({column})", f"expected a finite number, got {text!r}")
    return value


def _optional_shape(path: Path, line: int, row: dict[str, str], columns: tuple[str, ...]) -> list[float] | None:
    """The numbers of a circle or square when every one of its columns is filled, else None."""
    if not all(row.get(c) for c in columns):
        return None
    return [_number(path, line, c, row[c]) for c in columns]


def read_aspect_table(path: Path) -> list[dict]:
    """One entry per row of `aspects.csv`: number, modes, certificate, optional circle and square,
    and every cell as text (shown by the page)."""
    header, rows = read_csv_table(path, ("aspect",))
    out = []
    for line, row in rows:
        number = _number(path, line, "aspect", row["aspect"], integer=True)
        if number < 1:
            raise InputError(str(path), f"line {line} (aspect)", f"expected a number from 1, got {number}")
        out.append({
            "aspect": number,
            "working_mode": row.get("working_mode", ""),
            "assembly_mode": row.get("assembly_mode", ""),
            "det_sign": row.get("det_sign", ""),
            "certified": row.get("certified", ""),
            "circle": _optional_shape(path, line, row, CIRCLE),
            "square": _optional_shape(path, line, row, SQUARE),
            "cells": [[h, row[h]] for h in header],
        })
    return out


def read_crossing_table(path: Path) -> list[dict]:
    """The edges of the crossings graph from `aspects-adjacency.csv`."""
    _, rows = read_csv_table(path, ("aspect_a", "aspect_b", "singularity"))
    return [{"a": _number(path, line, "aspect_a", row["aspect_a"], integer=True),
             "b": _number(path, line, "aspect_b", row["aspect_b"], integer=True),
             "singularity": row["singularity"], "assembly_mode": row.get("assembly_mode", "")}
            for line, row in rows]


def read_path_table(path: Path) -> dict:
    """`path.csv`: its numeric columns (named after the axes they run along) and rows."""
    header, rows = read_csv_table(path)
    if len(rows) > MAX_PATH_ROWS:
        raise InputError(str(path), f"line {MAX_PATH_ROWS + 2}", f"more than {MAX_PATH_ROWS} rows")
    values = [[_number(path, line, h, row[h]) for h in header] for line, row in rows]
    return {"label": path.name, "columns": header, "rows": values}
