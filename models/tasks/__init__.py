"""Tasks: pick stations in the warehouse and the task source's book of tasks and claims."""
