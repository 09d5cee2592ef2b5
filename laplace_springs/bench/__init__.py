"""The error-against-run-time harness: its battery of stiff and extreme scenes, the peers
it measures, its independent reference (matrix exponentials), and its report.
"""
