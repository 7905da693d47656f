"""Tools for mission analysts: one satellite's lifetime, a catalogue, the disposal rule, the density fit."""
