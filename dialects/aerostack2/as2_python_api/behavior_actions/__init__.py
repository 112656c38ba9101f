"""Aerostack2's behavior handlers: a behavior started, waited for, polled or stopped."""
