"""Rules in the belief memory: checked and put in strata, evaluated bottom-up set at a time, kept up to date by
differences, and explained by proofs."""
