#!/usr/bin/python3
# SPDX-License-Identifier: MIT
"""Renders a data sheet JSON (written by hrg::characterize::DataSheet) into
summary.txt and one self-contained report.html (tables, PNG plots inlined as
base64, no network) in OUT_DIR. Usage: datasheet.py SHEET.json OUT_DIR"""
import base64
import html
import io
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def number(v, digits=4):
    """A figure for people: None (JSON null) is a dash."""
    if v is None:
        return "-"
    if v != 0 and (abs(v) >= 1e5 or abs(v) < 1e-3):
        return f"{v:.{digits - 1}e}"
    return f"{v:.{digits}g}"


def uncertainty(f):
    """'+- sigma' or '[lo, hi]', whichever the figure states."""
    if f.get("sigma") is not None:
        return "+- " + number(f["sigma"], 2)
    if f.get("lo") is not None and f.get("hi") is not None:
        return f"[{number(f['lo'])}, {number(f['hi'])}]"
    return ""


def render_plot(p):
    """One plot as PNG bytes (the style of tools/plots/sim_plots.py)."""
    fig, ax = plt.subplots(figsize=(7, 4.2))
    for s in p["series"]:
        x, y = s["x"], s["y"]
        if s["style"] == "errorbar" and "lo" in s:
            err = [[yi - lo for yi, lo in zip(y, s["lo"])], [hi - yi for yi, hi in zip(y, s["hi"])]]
            ax.errorbar(x, y, yerr=err, fmt="o-", ms=3, capsize=2, label=s["label"])
        elif s["style"] == "points":
            ax.plot(x, y, "o", ms=4, label=s["label"])
        else:
            ax.plot(x, y, "-", label=s["label"])
    if p["log_x"]:
        ax.set_xscale("log")
    if p["log_y"]:
        ax.set_yscale("log")
    ax.set_xlabel(p["x_label"])
    ax.set_ylabel(p["y_label"])
    ax.set_title(p["title"])
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    plt.close(fig)
    return buf.getvalue()


def html_table(title, columns, rows, cls):
    out = [f'<table class="{cls}"><caption>{html.escape(title)}</caption><tr>']
    out += [f"<th>{html.escape(c)}</th>" for c in columns]
    out.append("</tr>")
    for r in rows:
        out.append("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in r) + "</tr>")
    out.append("</table>")
    return "".join(out)


def section_html(sec):
    parts = [f'<section id="{html.escape(sec["id"])}"><h2>{html.escape(sec["title"])}</h2>',
             f'<p class="standard">{html.escape(sec["standard"])}</p>']
    figs = [[f["name"], number(f["value"]), uncertainty(f), f["unit"], f["note"]]
            for f in sec.get("figures", [])]
    parts.append(html_table("Figures", ["figure", "value", "uncertainty", "unit", "how"], figs,
                            "figures"))
    for t in sec.get("tables", []):
        parts.append(html_table(t["title"], t["columns"], t["rows"], "data"))
    for p in sec.get("plots", []):
        png = base64.b64encode(render_plot(p)).decode("ascii")
        parts.append(f'<figure><img id="plot-{html.escape(p["id"])}" alt="{html.escape(p["title"])}"'
                     f' src="data:image/png;base64,{png}"><figcaption>{html.escape(p["title"])}'
                     "</figcaption></figure>")
    parts.append("</section>")
    return "\n".join(parts)


STYLE = """body{font-family:sans-serif;margin:2em;max-width:70em}
table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #bbb;padding:.2em .6em}
th{background:#eee}caption{font-weight:bold;text-align:left}.standard{color:#555}
figure img{max-width:100%}"""
# Marks the body with how many images decoded: a headless browser's DOM dump
# then shows that the figures are there, not only their tags.
CHECK = """<script>window.addEventListener('load',function(){var n=0;
for(var i of document.images){if(i.complete&&i.naturalWidth>0)n++;}
document.body.setAttribute('data-images-decoded',String(n));});</script>"""


def write_html(sheet, path):
    body = "\n".join(section_html(s) for s in sheet["sections"])
    title = html.escape(sheet["title"])
    with open(path, "w") as f:
        f.write(f"<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>{title}</title>"
                f"<style>{STYLE}</style>{CHECK}</head>\n<body><h1>{title}</h1>\n{body}\n"
                "</body></html>\n")


def write_summary(sheet, path):
    lines = [sheet["title"], "=" * len(sheet["title"])]
    for s in sheet["sections"]:
        lines += ["", f"{s['title']} ({s['standard']})"]
        for f in s.get("figures", []):
            lines.append(f"  {f['name']:<42} {number(f['value']):>12} {uncertainty(f):<24} "
                         f"{f['unit']}")
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def main(sheet_path, out):
    with open(sheet_path) as f:
        sheet = json.load(f)
    for s in sheet.get("sections", []):
        for k in ("id", "title", "standard"):
            if k not in s:
                sys.exit(f"{sheet_path}: a section has no '{k}'")
        for f in s.get("figures", []):
            if f.get("value") is not None and not math.isfinite(f["value"]):
                sys.exit(f"{sheet_path}: figure '{f['name']}' is not finite")
    os.makedirs(out, exist_ok=True)
    write_summary(sheet, os.path.join(out, "summary.txt"))
    write_html(sheet, os.path.join(out, "report.html"))
    print("data sheet: summary.txt report.html in " + out)


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.stderr.write("usage: datasheet.py SHEET.json OUT_DIR\n")
        sys.exit(2)
    main(sys.argv[1], sys.argv[2])
