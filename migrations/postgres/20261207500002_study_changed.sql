-- A study begun or removed changes what the manifest says (its
-- `study_results` link, issue 45), so it bumps the change counter like a
-- model version does (and notifies the other instances). Keep in step with
-- ../sqlite/.
CREATE TRIGGER study_changed AFTER INSERT OR DELETE ON study
    FOR EACH STATEMENT EXECUTE FUNCTION vitrine_changed();
