"""The words of a judgement, shared by the code that judges (omniloc.paper) and the writer that
colours them (omniloc.tools.markup): a claim's verdict, and the status of a cause of a verdict that
does not hold (omniloc.paper.causes)."""
from __future__ import annotations

# A claim's verdict by the rule written next to it in papers.json (omniloc.paper.claims).
HOLDS, PARTLY, DOES_NOT, NOT_RUN, NOT_APPLICABLE = "holds", "partly", "does not", "not run", "n/a"

# The status of a cause: every measurement it rests on in these results and inside its range
# (explained); some not measured; some outside (contradicts); or no cause written down.
EXPLAINED, NOT_MEASURED, CONTRADICTED, UNEXPLAINED = "explained", "evidence not in these results", "evidence contradicts the cause", "no cause recorded"
CAUSE_STATUSES = (EXPLAINED, NOT_MEASURED, CONTRADICTED, UNEXPLAINED)
