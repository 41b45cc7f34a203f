"""Typography shared by the figures: units and symbols as the dissertation prints them.

Axis labels are written with these constants; titles and case labels come from run files
(ASCII, e.g. "S0 = 6 um, theta_H = 10 deg") and pass through typeset() before they are drawn.
The micro sign is the plain character (U+00B5, upright in DejaVu Sans, Debian's default font),
not mathtext's italic $\\mu$.
"""

import re

UM = "\u00b5m"  # µm
UM_PAREN = f"({UM})"

# ASCII spelling in run files -> what the figure shows. Applied in this order, each only where
# the ASCII spelling stands as a word of its own.
_WORDS = [
    (r"mu0\s*H_?C([12])", r"$\\mu_0 H_{C\1}$"),
    (r"theta_H", r"$\\theta_H$"),
    (r"theta", "\u03b8"),  # θ
    (r"Phi", "\u03a6"),  # Φ
    (r"S0", r"$S_0$"),
    (r"mu0", "\u03bc\u2080"),  # μ₀
    (r"um", UM),
]
_DEGREES = re.compile(r"(\d)\s*deg\b")


def typeset(text):
    """'S0 = 6 um, theta_H = 10 deg' -> '$S_0$ = 6 µm, $\\theta_H$ = 10°'. Text that already
    holds mathtext ($) is left as it is: its author typeset it."""
    if not text or "$" in text:
        return text
    for ascii_spelling, shown in _WORDS:
        text = re.sub(rf"(?<![A-Za-z0-9_]){ascii_spelling}(?![A-Za-z0-9_])", shown, text)
    return _DEGREES.sub("\\1\u00b0", text)


def suptitle(run, fig, fontsize=11):
    """The run's title (run file [run].title) over the figure, typeset."""
    if run.title:
        fig.suptitle(typeset(run.title), fontsize=fontsize)
