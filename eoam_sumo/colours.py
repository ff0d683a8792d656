"""The outcome colours of a run (paper sec. 11): their names, plot colours, table markers and
one-line meanings, in one place for the outcome rules, the matrix, the report and the plots.
"""

from __future__ import annotations

#: Outcome colours, mildest first; ``unfinished`` (no colour of the paper's) last.
OUTCOMES = ("none", "green", "yellow", "orange", "red", "unfinished")
#: A batch case that did not finish (a worker error, not an outcome of the physics).
FAILED = "failed"
#: Plot colour of each outcome; grey for none, dark grey for a failed case.
HEX = {
    "green": "#43a047",
    "yellow": "#fdd835",
    "orange": "#fb8c00",
    "red": "#e53935",
    "none": "#bdbdbd",
    "unfinished": "#8e24aa",
    FAILED: "#616161",
}
#: Markdown marker of each outcome.
MARKERS = {
    "green": "🟩",
    "yellow": "🟨",
    "orange": "🟧",
    "red": "🟥",
    "none": "⬜",
    "unfinished": "🟪",
    FAILED: "⚠️",
}
#: Paper sec. 11 colour definitions, shortened (the table legend).
LEGEND = {
    "green": "lane change completed without collision and back in lane (or stopped, no contact)",
    "yellow": "straight-line limit braking chosen, front hit on the ARO at reduced speed",
    "orange": "lane change made, lateral (side) contact",
    "red": "lane change made, head-on (direct or offset) hit on the oncoming vehicle",
    "none": "no manoeuvre needed, nothing hit",
    "unfinished": "cut off at the time limit mid-manoeuvre or out of lane, nothing hit yet",
    FAILED: "the case did not finish (see the error)",
}
#: Outcomes drawn in black text on their colour (the rest in white).
DARK_TEXT = ("yellow", "none", "orange")
