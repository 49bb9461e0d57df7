"""The report (`omniloc report`): one module per section, assembled in reading order by
omniloc.report.assemble, written through omniloc.tools.markup and drawn by omniloc.tools.plot."""
