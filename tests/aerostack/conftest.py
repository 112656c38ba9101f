"""The collected missions under data/ are data, not tests (some of them are named *_test.py)."""

collect_ignore = ["data"]
