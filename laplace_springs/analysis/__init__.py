"""Stage 4, analysis: modes (frequencies, damping ratios, shapes) and frequency response."""
