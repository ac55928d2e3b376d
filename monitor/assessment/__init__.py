"""The assessment of a day: granules or reference collocations in, the typed result out."""
