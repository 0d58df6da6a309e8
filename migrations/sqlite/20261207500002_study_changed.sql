-- A study begun or removed changes what the manifest says (its
-- `study_results` link, issue 45), so it bumps the change counter like a
-- model version does: a `vitrine study create` beside a running service
-- shows within the poll interval. Keep in step with ../postgres/.
CREATE TRIGGER study_insert_changed AFTER INSERT ON study BEGIN UPDATE change_generation SET generation = generation + 1; END;
CREATE TRIGGER study_delete_changed AFTER DELETE ON study BEGIN UPDATE change_generation SET generation = generation + 1; END;
