"""The report's tables: one value per cell, formatted once, written as HTML, Markdown, CSV and LaTeX.

Numbers are given to ``SIGNIFICANT`` significant digits in positional notation (never fewer than the
integer digits: 20966 stays 20966), p-values to two significant digits (scientific below 0.001); a missing
value is an en dash.  A cell may hold a pair (mean, std), shown ``mean ± std`` and written to the CSV as two
columns.  The CSV keeps the full precision of the numbers; the LaTeX table (``booktabs``:
``\\toprule``, ``\\midrule``, ``\\bottomrule``) holds what the HTML shows.
"""

from __future__ import annotations

import csv
import html
import io
import math
import re
from dataclasses import dataclass, field
from typing import Any

import numpy as np

SIGNIFICANT = 4
MISSING = "–"


def number(x: Any, significant: int = SIGNIFICANT) -> str:
    """``x`` to ``significant`` digits, positional (see the module docstring)."""
    if x is None or (isinstance(x, float) and math.isnan(x)):
        return MISSING
    if isinstance(x, (bool, np.bool_)):
        return "yes" if x else "no"
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    if isinstance(x, (float, np.floating)):
        x = float(x)
        if math.isinf(x):
            return "∞" if x > 0 else "-∞"
        if x == 0:
            return "0"
        digits = max(significant, int(math.floor(math.log10(abs(x)))) + 1)
        return np.format_float_positional(x, precision=digits, unique=False, fractional=False, trim="-")
    return str(x)


def p_value(p: Any) -> str:
    """A p-value to two significant digits, scientific below 0.001."""
    if p is None or (isinstance(p, float) and math.isnan(p)):
        return MISSING
    p = float(p)
    return f"{p:.1e}" if 0 < p < 1e-3 else number(p, 2)


@dataclass(frozen=True)
class Pair:
    """A mean ± std cell."""

    mean: float | None
    std: float | None

    def text(self) -> str:
        if self.mean is None or (isinstance(self.mean, float) and math.isnan(self.mean)):
            return MISSING
        return number(self.mean) if self.std is None or math.isnan(self.std) else \
            f"{number(self.mean)} ± {number(self.std)}"


@dataclass
class Table:
    """A titled table; ``kinds`` per column: "text", "number", "p" or "pair" (default: by value)."""

    name: str  # file stem of its CSV and LaTeX files
    caption: str
    header: list[str]
    rows: list[list[Any]]
    kinds: dict[int, str] = field(default_factory=dict)

    def cell(self, column: int, value: Any) -> str:
        kind = self.kinds.get(column)
        if isinstance(value, Pair):
            return value.text()
        if kind == "p":
            return p_value(value)
        return number(value)

    def text_rows(self) -> list[list[str]]:
        return [[self.cell(i, v) for i, v in enumerate(row)] for row in self.rows]

    def html(self) -> str:
        head = "".join(f"<th>{html.escape(h)}</th>" for h in self.header)
        body = "".join("<tr>" + "".join(f"<td{' class=t' if _is_text(v) else ''}>{html.escape(c)}</td>"
                                        for v, c in zip(raw, row)) + "</tr>"
                       for raw, row in zip(self.rows, self.text_rows()))
        return f"<div class='table'><table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table></div>"

    def markdown(self) -> list[str]:
        lines = ["| " + " | ".join(self.header) + " |", "|" + "---|" * len(self.header)]
        lines += ["| " + " | ".join(c.replace("|", "\\|") for c in row) + " |" for row in self.text_rows()]
        return lines + [""]

    def csv(self) -> str:
        """Full precision; a mean ± std column becomes two (``... mean``, ``... std``)."""
        pairs = {i for row in self.rows for i, v in enumerate(row) if isinstance(v, Pair)}
        header = []
        for i, h in enumerate(self.header):
            header += [f"{h} mean", f"{h} std"] if i in pairs else [h]
        buffer = io.StringIO()
        writer = csv.writer(buffer, lineterminator="\n")
        writer.writerow(header)
        for row in self.rows:
            out = []
            for i, v in enumerate(row):
                if i in pairs:
                    out += [_raw(v.mean), _raw(v.std)] if isinstance(v, Pair) else [_raw(v), ""]
                else:
                    out.append(_raw(v))
            writer.writerow(out)
        return buffer.getvalue()

    def latex(self) -> str:
        """A ``booktabs`` table (needs ``\\usepackage{booktabs}``): first column left, the others right."""
        spec = "l" + "r" * (len(self.header) - 1)
        lines = [r"\begin{table}[htbp]", r"\centering", rf"\caption{{{latex_escape(self.caption)}}}",
                 rf"\begin{{tabular}}{{{spec}}}", r"\toprule",
                 " & ".join(latex_escape(h) for h in self.header) + r" \\", r"\midrule"]
        lines += [" & ".join(latex_escape(c) for c in row) + r" \\" for row in self.text_rows()]
        lines += [r"\bottomrule", r"\end{tabular}", r"\end{table}", ""]
        return "\n".join(lines)


def _is_text(value: Any) -> bool:
    """A cell set left (text), as opposed to a number or a count like "3/10" (right)."""
    return isinstance(value, str) and not re.fullmatch(r"[\d/.% -]*", value)


def _raw(value: Any) -> Any:
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return ""
    if isinstance(value, (np.floating, float)):
        return repr(float(value))
    return value


_LATEX = {"\\": r"\textbackslash{}", "&": r"\&", "%": r"\%", "$": r"\$", "#": r"\#", "_": r"\_", "{": r"\{",
          "}": r"\}", "~": r"\textasciitilde{}", "^": r"\textasciicircum{}", "±": r"$\pm$", "–": "--",
          "×": r"$\times$", "≡": r"$\equiv$", "∞": r"$\infty$", "²": r"$^2$", "≥": r"$\geq$", "≤": r"$\leq$",
          "<": r"\textless{}", ">": r"\textgreater{}", "·": r"$\cdot$"}


def latex_escape(text: str) -> str:
    """Text safe in a LaTeX table with the base fonts (the characters the report uses are mapped; any other
    non-ASCII character becomes '?', so ``pdflatex`` never fails on it)."""
    out = []
    for ch in str(text):
        if ch in _LATEX:
            out.append(_LATEX[ch])
        elif ord(ch) < 128:
            out.append(ch)
        else:
            out.append("?")
    return "".join(out)
