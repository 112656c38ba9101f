"""A stand-in for Aerostack2's ``as2_msgs``: the constants of its messages that missions compare with (``msg``)."""
