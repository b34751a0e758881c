"""Regression: checking the RTL against the golden model. Constrained-random command
streams (`randgen`) and their functional coverage (`coverage`), used by the cocotb
scoreboards in tb/; and `make sim` (docs/regression.md), split by concern: the manifest's
cases and their streams (`cases`), running a case and analysing a failure (`run`), the
terminal/JUnit/HTML reports (`report`), duration-balanced shards (`shards`), a run's
outputs and the merge of shards (`merge`), and the command line (`main`, reached as
`diffengine sim`).
"""
