"""Agents: scripted behaviours of the paper and (later) learned policies."""
