"""The β_h batches: how the workflow cuts mesh pairs into jobs, β_h of one batch for any model,
the elastic pair beside the membranes, and the rows a figure shows."""
