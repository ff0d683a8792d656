"""What shows a folder holds a batch's output (``eoam-sumo batch``, ``eoam-sumo bench
--studies``): a re-run over it is staged and replaces it once complete."""

from __future__ import annotations

from eoam_sumo.batch.probabilities import PROBABILITIES_FILE
from eoam_sumo.batch.report import TABLE_MD
from eoam_sumo.batch.results import CASES_DIR, RESULTS_FILE
from eoam_sumo.outputs.staging import OutputKind

BATCH_OUTPUT = OutputKind(
    "batch",
    (RESULTS_FILE, CASES_DIR, TABLE_MD, PROBABILITIES_FILE),
    foreign=("batch", "scorecard.md", "scorecard.png", "runs"),
)
