"""The papers' side: the published tables paired with our runs, the claims judged by the rules
written next to them (papers.json: data), the causes of verdicts that do not hold, and the reader's
labels of claims and tables (omniloc.paper.data: data apart from the code that judges)."""
