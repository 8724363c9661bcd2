"""The paper's Appendix B checked on traces, and the numbers of ``docs/paper.md``."""
