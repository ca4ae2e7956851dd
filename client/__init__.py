"""Data package: the browser client (plain ES modules and pages), served by lipclock.net."""
