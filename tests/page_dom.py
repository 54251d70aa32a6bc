"""Reading a preview page back as a browser would get it (a DOM check, no browser): the plotly figures' JSON
embedded in the page and the rows of its results table.

Used by the unit tests of the page (a synthetic run) and the scenario test of ``cell preview fence1``.
"""

from __future__ import annotations

import json
import re
from html.parser import HTMLParser
from pathlib import Path
from typing import Any


def figures(page: str) -> dict[str, dict[str, Any]]:
    """div id -> {"data": [...traces], "layout": {...}} of every ``Plotly.newPlot("id", data, layout, ...)``."""
    out: dict[str, dict[str, Any]] = {}
    dec = json.JSONDecoder()
    for m in re.finditer(r'Plotly\.newPlot\(\s*(?=")', page):  # the page's calls, not plotly.js's own code
        div, pos = dec.raw_decode(page, m.end())
        pos = page.index(",", pos) + 1
        while page[pos].isspace():
            pos += 1
        data, pos = dec.raw_decode(page, pos)
        pos = page.index(",", pos) + 1
        while page[pos].isspace():
            pos += 1
        layout, pos = dec.raw_decode(page, pos)
        out[str(div)] = {"data": data, "layout": layout}
    return out


class _Rows(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.rows: list[dict[str, Any]] = []
        self._in_results = False
        self._cell: list[str] | None = None

    def handle_starttag(self, tag: str, attrs: list[tuple[str, str | None]]) -> None:
        a = dict(attrs)
        if tag == "table" and a.get("id") == "results":
            self._in_results = True
        elif self._in_results and tag == "tr" and "data-seam" in a:
            self.rows.append({"seam": a["data-seam"], "status": a.get("data-status"), "cells": []})
        elif self._in_results and tag == "td" and self.rows:
            self._cell = []

    def handle_data(self, data: str) -> None:
        if self._cell is not None:
            self._cell.append(data)

    def handle_endtag(self, tag: str) -> None:
        if tag == "td" and self._cell is not None:
            self.rows[-1]["cells"].append("".join(self._cell).strip())
            self._cell = None
        elif tag == "table":
            self._in_results = False


def results_rows(page: str) -> list[dict[str, Any]]:
    """The rows of ``<table id="results">``: seam, status and the cells' text."""
    p = _Rows()
    p.feed(page)
    return p.rows


def read(path: Path) -> tuple[dict[str, dict[str, Any]], list[dict[str, Any]]]:
    text = path.read_text(encoding="utf-8")
    return figures(text), results_rows(text)
