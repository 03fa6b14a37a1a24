"""The reproduction of the dissertation: its tables, the Appendix D tire fits, the six
thesis vehicles, the chapter III-V studies and the audit of every published number."""
