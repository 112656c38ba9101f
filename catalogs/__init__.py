"""The behavior catalogs shipped with aeroexec, as package data: the aerial catalog (``aerial.yaml``, the paper's
Appendix B format) that ``aeroexec run`` and ``verify`` use unless ``--catalog`` names another."""
