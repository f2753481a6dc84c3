"""The program's process: signals as stop requests, forked children, private temporary files, progress bars."""
