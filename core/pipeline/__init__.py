"""The commands as library calls: plan, execute, check and benchmark compose the districts below.

Modules: `plan` (plan, plan_to_file; one step's stages in `step`), `request` (PlanFlags,
resolve_request), `execute` (execute, check), `plan_files` (what every command reading a plan
needs: its config, its steps checked, its controller), `report` (the result document and the
executed file), `inspection` (inspect_file), `benchmark` (run_benchmark, summarize), `plots/`
(the --plot files). Nothing is imported
here, so that a command loads only what it runs (execute never loads OMPL).
"""
