"""The seed's "25 atomic instructions" (section 7.6.1) against our 19 identifiers
(docs/isa.md section 3.1): every cell of Table 7.2 maps to one identifier of ours, the
seed's count follows from the table when the Eval1-3 address slot and the Accumulate slot
are each one instruction, and the cells our identifiers share account for 25 -> 17
(plus the two EvalN identifiers, 19)."""
from diffengine import isa

S = 1 << isa.FRAC_BITS
# One command per Table 7.2 row (Eval1..3 with one value each order).
ROWS = {
    "Eval0": isa.Command("EVAL0", 1, 2, (100,)),
    "Eval1": isa.Command("EVAL", 1, 2, (S,)),
    "Eval2": isa.Command("EVAL", 1, 2, (S, S)),
    "Eval3": isa.Command("EVAL", 1, 2, (S, S, S)),
    "SetI": isa.Command("SETI", 1, 0, (S,)),
    "SetdI": isa.Command("SETDI", 1, 0, (S,)),
    "SetddI": isa.Command("SETDDI", 1, 0, (S,)),
    "SetPI": isa.Command("SETPI", 1, 2, (S,)),
    "SetPdI": isa.Command("SETPDI", 1, 2, (S,)),
    "SetPddI": isa.Command("SETPDDI", 1, 2, (S,)),
    "Dis": isa.Command("DIS", 1, 2),
    "Acc_mode": isa.Command("ACCMODE", values=(1,)),
    "Refresh": isa.Command("REFRESH"),
    "Nop": isa.Command("NOP"),
}
# Table 7.2's cells, time slot by time slot (the seed's wording).
TABLE_7_2 = {
    "Eval0": ["X, dX, I"],
    "Eval1": ["X, dX", "I", "Accumulate"],
    "Eval2": ["X, dX", "dI", "I", "Accumulate"],
    "Eval3": ["X, dX", "ddI", "dI", "I", "Accumulate"],
    "SetI": ["X", "I"], "SetdI": ["X", "dI"], "SetddI": ["X", "ddI"],
    "SetPI": ["X, dX", "I"], "SetPdI": ["X, dX", "dI"], "SetPddI": ["X, dX", "ddI"],
    "Dis": ["X, dX"], "Acc_mode": ["Enable/Disable"], "Refresh": ["Refresh"],
    "Nop": ["No operation"],
}


def _seed_instruction(cmd: str, cell: str) -> str:
    """The seed's atomic instruction of a cell under the reading that gives 25: the
    Eval1-3 address slot is one instruction, so is their Accumulate slot; every other
    cell is its own."""
    if cmd in ("Eval1", "Eval2", "Eval3") and cell in ("X, dX", "Accumulate"):
        return f"Eval {cell}"
    return f"{cmd} {cell}"


def test_every_table_7_2_cell_is_one_of_our_slots():
    assert len(ROWS) == 14                      # Table 7.1's commands, with Nop
    for name, cmd in ROWS.items():
        assert len(isa.slots(cmd)) == len(TABLE_7_2[name]), name


def test_the_seeds_count_of_25_from_table_7_2():
    cells = [(c, cell) for c, cs in TABLE_7_2.items() for cell in cs]
    assert len(cells) == 29
    assert len({_seed_instruction(c, cell) for c, cell in cells}) == 25


def test_our_identifiers_merge_the_seeds_25_into_17_plus_2_for_evaln():
    ours = {}
    for name, cmd in ROWS.items():
        for cell, (ident, _) in zip(TABLE_7_2[name], isa.slots(cmd)):
            ours.setdefault(_seed_instruction(name, cell), set()).add(
                ident if name != "Acc_mode" else "ACCMODE")
    assert all(len(v) == 1 for v in ours.values())        # one identifier per seed instruction
    seed_to_ours = {k: next(iter(v)) for k, v in ours.items()}
    used = {isa.ACCMODE_ON, isa.ACCMODE_OFF} | {v for v in seed_to_ours.values() if v != "ACCMODE"}
    assert len(used) == 17
    # the merges of docs/isa.md 3.1
    assert seed_to_ours["Eval2 I"] == seed_to_ours["Eval3 I"] == isa.D_A_B
    assert {seed_to_ours[f"{c} X"] for c in ("SetI", "SetdI", "SetddI")} == {isa.ADDR_RANGE}
    assert seed_to_ours["Eval X, dX"] == isa.ADDR_RANGE
    assert {seed_to_ours[f"{c} X, dX"] for c in ("SetPI", "SetPdI", "SetPddI")} == {isa.ADDR_PERIODIC}
    assert seed_to_ours["SetI I"] == seed_to_ours["SetPI I"] == isa.SET_A
    assert seed_to_ours["SetdI dI"] == seed_to_ours["SetPdI dI"] == isa.SET_B
    assert seed_to_ours["SetddI ddI"] == seed_to_ours["SetPddI ddI"] == isa.SET_C
    # EvalN (N >= 4, our extension) adds the two unprotected data identifiers
    evaln = {i for i, _ in isa.slots(isa.Command("EVAL", 1, 2, (S,) * 5))}
    assert used | evaln == set(isa.LUT_INDEX) and len(used | evaln) == 19
