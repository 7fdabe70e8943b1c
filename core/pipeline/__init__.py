"""The commands as library calls: plan, execute, check and benchmark compose the districts below.

Modules: `plan` (resolve_request, plan), `execute` (execute, check), `report` (the result
document and the executed file), `benchmark` (run_benchmark, summarize). Nothing is imported
here, so that a command loads only what it runs (execute never loads OMPL).
"""
